// CG start from x = 0 with the residual r already uploaded (masked): z = M^-1 r (Jacobi),
// p = z, x = 0, written in one pass to three render targets.
uniform sampler2D u_r;
uniform sampler2D u_minv;  // 1/diag on free DOFs, 0 on constrained DOFs and padding
layout(location = 0) out float o_x;
layout(location = 1) out float o_z;
layout(location = 2) out float o_p;

void main() {
  ivec2 c = ivec2(gl_FragCoord.xy);
  float z = texelFetch(u_minv, c, 0).r * texelFetch(u_r, c, 0).r;
  o_x = 0.0;
  o_z = z;
  o_p = z;
}
