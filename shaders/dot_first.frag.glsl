// First pass of a dot product (docs/DESIGN.md section 9, "sum reduction"): each output texel
// multiplies and sums a u_fan_in x u_fan_in block of two vectors, giving (sum a*b, sum a*a) in RG:
// (r.z, r.r) in one go for CG, or (p.q, -) for alpha.
uniform sampler2D u_a;
uniform sampler2D u_b;
uniform ivec2 u_src_size;
uniform int u_fan_in;
layout(location = 0) out vec2 o_sum;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * u_fan_in;
  ivec2 end = min(base + ivec2(u_fan_in), u_src_size);
  vec2 s = vec2(0.0);
  for (int j = base.y; j < end.y; ++j)
    for (int i = base.x; i < end.x; ++i) {
      float a = texelFetch(u_a, ivec2(i, j), 0).r;
      s += vec2(a * texelFetch(u_b, ivec2(i, j), 0).r, a * a);
    }
  o_sum = s;
}
