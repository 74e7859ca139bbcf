// Halving pass of a sum reduction (docs/DESIGN.md section 9): each output texel sums a 2x2 block
// of the previous level (RG channels); repeated, ping-ponging down the chain, until 1x1.
uniform sampler2D u_src;
uniform ivec2 u_src_size;
layout(location = 0) out vec2 o_sum;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * 2;
  vec2 s = vec2(0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      ivec2 q = base + ivec2(i, j);
      if (q.x < u_src_size.x && q.y < u_src_size.y) s += texelFetch(u_src, q, 0).rg;
    }
  o_sum = s;
}
