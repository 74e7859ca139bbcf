// CG step length alpha = (r.z) / (p.A p) into a 1x1 texture, so it never leaves the GPU.
// A non-positive p.Ap (breakdown, or r already exactly 0) gives alpha = 0: the iterate stays.
uniform sampler2D u_rz;  // 1x1 RG: (r.z, r.r)
uniform sampler2D u_pq;  // 1x1 RG: (p.q, p.p)
layout(location = 0) out float o_alpha;

void main() {
  float rz = texelFetch(u_rz, ivec2(0), 0).r;
  float pq = texelFetch(u_pq, ivec2(0), 0).r;
  o_alpha = pq > 0.0 ? rz / pq : 0.0;
}
