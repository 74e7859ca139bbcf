// SpMV y = A x, Method A of the paper (docs/DESIGN.md section 9): Telement holds ONE off-diagonal
// non-zero per texel (value bits and column packed in an RG32I texel), Tindex the row's start
// texel and count. Pass k adds the k-th non-zero of every row, so a full SpMV needs as many
// passes as the longest row; the running sum ping-pongs between two render targets.
uniform sampler2D u_x;          // R32F vector
uniform sampler2D u_diag;       // R32F diagonal, stored apart
uniform sampler2D u_prev;       // R32F partial sums of passes 0..k-1
uniform isampler2D u_tindex;    // RG32I (start, count)
uniform isampler2D u_telement;  // RG32I (floatBitsToInt(value), column)
uniform int u_pass;
uniform int u_vec_shift;
uniform int u_elem_shift;
layout(location = 0) out float o_y;

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  float acc = u_pass == 0 ? texelFetch(u_diag, p, 0).r * texelFetch(u_x, p, 0).r
                          : texelFetch(u_prev, p, 0).r;
  ivec2 ti = texelFetch(u_tindex, p, 0).rg;
  if (u_pass < ti.y) {
    int e = ti.x + u_pass;
    ivec2 te = texelFetch(u_telement, ivec2(e & ((1 << u_elem_shift) - 1), e >> u_elem_shift), 0).rg;
    int c = te.y;
    acc += intBitsToFloat(te.x) *
           texelFetch(u_x, ivec2(c & ((1 << u_vec_shift) - 1), c >> u_vec_shift), 0).r;
  }
  o_y = acc;
}
