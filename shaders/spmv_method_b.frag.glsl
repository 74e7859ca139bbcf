// SpMV y = A x, Method B of the paper (docs/DESIGN.md section 9): four off-diagonal non-zeros per
// RGBA32F Telement texel (rows padded to a multiple of 4 with zeros), their x texel
// coordinates in two index textures Tst-a (s0,t0,s1,t1) and Tst-b (s2,t2,s3,t3). Pass k adds
// the k-th group of four: ceil(longest row / 4) passes, ping-pong as in Method A.
uniform sampler2D u_x;
uniform sampler2D u_diag;
uniform sampler2D u_prev;
uniform isampler2D u_tindex;    // RG32I (start texel, texel count)
uniform sampler2D u_telement;   // RGBA32F
uniform isampler2D u_tst_a;     // RGBA32I
uniform isampler2D u_tst_b;     // RGBA32I
uniform int u_pass;
uniform int u_elem_shift;
layout(location = 0) out float o_y;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float acc = u_pass == 0 ? texelFetch(u_diag, p, 0).r * texelFetch(u_x, p, 0).r
                          : texelFetch(u_prev, p, 0).r;
  ivec2 ti = texelFetch(u_tindex, p, 0).rg;
  if (u_pass < ti.y) {
    int e = ti.x + u_pass;
    ivec2 ec = ivec2(e & ((1 << u_elem_shift) - 1), e >> u_elem_shift);
    vec4 v = texelFetch(u_telement, ec, 0);
    ivec4 a = texelFetch(u_tst_a, ec, 0);
    ivec4 b = texelFetch(u_tst_b, ec, 0);
    vec4 xs = vec4(texelFetch(u_x, a.xy, 0).r, texelFetch(u_x, a.zw, 0).r,
                   texelFetch(u_x, b.xy, 0).r, texelFetch(u_x, b.zw, 0).r);
    acc += dot(v, xs);
  }
  o_y = acc;
}
