// CG vector updates in one pass, three render targets: x += alpha p, r -= alpha q, z = M^-1 r.
// Projected CG (linear_solver.hpp): the mask zeroes r on constrained DOFs (and padding), so
// z and p stay 0 there and x keeps its entry value; q = A p itself is not masked.
uniform sampler2D u_x;
uniform sampler2D u_r;
uniform sampler2D u_p;
uniform sampler2D u_q;
uniform sampler2D u_mask;   // 1 free, 0 constrained / padding
uniform sampler2D u_minv;
uniform sampler2D u_alpha;  // 1x1
layout(location = 0) out float o_x;
layout(location = 1) out float o_r;
layout(location = 2) out float o_z;

void main() {
  ivec2 c = ivec2(gl_FragCoord.xy);
  float alpha = texelFetch(u_alpha, ivec2(0), 0).r;
  float r = texelFetch(u_mask, c, 0).r * (texelFetch(u_r, c, 0).r - alpha * texelFetch(u_q, c, 0).r);
  o_x = texelFetch(u_x, c, 0).r + alpha * texelFetch(u_p, c, 0).r;
  o_r = r;
  o_z = texelFetch(u_minv, c, 0).r * r;
}
