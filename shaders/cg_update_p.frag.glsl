// CG search direction p = z + beta p (beta from a 1x1 texture).
uniform sampler2D u_z;
uniform sampler2D u_p;
uniform sampler2D u_beta;
layout(location = 0) out float o_p;

void main() {
  ivec2 c = ivec2(gl_FragCoord.xy);
  o_p = texelFetch(u_z, c, 0).r + texelFetch(u_beta, ivec2(0), 0).r * texelFetch(u_p, c, 0).r;
}
