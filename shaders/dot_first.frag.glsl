// First pass of a dot product (docs/DESIGN.md section 9, "sum reduction: repeated halving
// passes"): each output texel multiplies and sums a 2x2 block of two vectors, giving
// (sum a*b, sum a*a) in RG: (r.z, r.r) in one go for CG, or (p.q, -) for alpha.
uniform sampler2D u_a;
uniform sampler2D u_b;
uniform ivec2 u_src_size;
layout(location = 0) out vec2 o_sum;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * 2;
  vec2 s = vec2(0.0);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      ivec2 q = base + ivec2(i, j);
      if (q.x < u_src_size.x && q.y < u_src_size.y) {
        float a = texelFetch(u_a, q, 0).r;
        s += vec2(a * texelFetch(u_b, q, 0).r, a * a);
      }
    }
  o_sum = s;
}
