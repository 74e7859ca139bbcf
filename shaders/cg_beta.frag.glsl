// CG direction update factor beta = (r.z)_new / (r.z)_old into a 1x1 texture.
uniform sampler2D u_rz_new;
uniform sampler2D u_rz_old;
layout(location = 0) out float o_beta;

void main() {
  float rz_old = texelFetch(u_rz_old, ivec2(0), 0).r;
  o_beta = rz_old > 0.0 ? texelFetch(u_rz_new, ivec2(0), 0).r / rz_old : 0.0;
}
