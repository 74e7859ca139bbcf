// SpMV y = A x in ONE pass (our layout, the paper's future work in docs/DESIGN.md section 9): the
// same 4-wide RGBA32F value blocks as Method B plus one RGBA32I texture of 4 columns; each
// fragment loops over its own row. The pass count is 1 whatever the longest row: dense
// interface rows cost their own fragments more time but no extra passes over the whole vector.
uniform sampler2D u_x;
uniform sampler2D u_diag;
uniform isampler2D u_tindex;    // RG32I (start texel, texel count)
uniform sampler2D u_telement;   // RGBA32F
uniform isampler2D u_tcols;     // RGBA32I, 4 columns
uniform int u_vec_shift;
uniform int u_elem_shift;
layout(location = 0) out float o_y;

float x_at(int c) {
  return texelFetch(u_x, ivec2(c & ((1 << u_vec_shift) - 1), c >> u_vec_shift), 0).r;
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float acc = texelFetch(u_diag, p, 0).r * texelFetch(u_x, p, 0).r;
  ivec2 ti = texelFetch(u_tindex, p, 0).rg;
  int emask = (1 << u_elem_shift) - 1;
  for (int e = ti.x; e < ti.x + ti.y; ++e) {
    ivec2 ec = ivec2(e & emask, e >> u_elem_shift);
    vec4 v = texelFetch(u_telement, ec, 0);
    ivec4 c = texelFetch(u_tcols, ec, 0);
    acc += dot(v, vec4(x_at(c.x), x_at(c.y), x_at(c.z), x_at(c.w)));
  }
  o_y = acc;
}
