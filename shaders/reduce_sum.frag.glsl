// One pass of a sum reduction (docs/DESIGN.md section 9): each output texel sums a
// u_fan_in x u_fan_in block of the previous level (RG channels); repeated, ping-ponging down the
// chain, until 1x1.
uniform sampler2D u_src;
uniform ivec2 u_src_size;
uniform int u_fan_in;
layout(location = 0) out vec2 o_sum;

void main() {
  ivec2 base = ivec2(gl_FragCoord.xy) * u_fan_in;
  ivec2 end = min(base + ivec2(u_fan_in), u_src_size);
  vec2 s = vec2(0.0);
  for (int j = base.y; j < end.y; ++j)
    for (int i = base.x; i < end.x; ++i) s += texelFetch(u_src, ivec2(i, j), 0).rg;
  o_sum = s;
}
