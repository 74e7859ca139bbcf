#include "soft_tissue_cutting/cutting/blade_path.hpp"

#include <algorithm>
#include <cmath>

namespace stc {

double blade_travel(const BladePose& a, const BladePose& b, double blade_length) {
  const Vec3 edge = Vec3::UnitX() * blade_length;
  const Vec3 heel_a = a.position + a.orientation.normalized() * edge;
  const Vec3 heel_b = b.position + b.orientation.normalized() * edge;
  return std::max((b.position - a.position).norm(), (heel_b - heel_a).norm());
}

double blade_path_length(const std::vector<BladePose>& poses, double blade_length) {
  double length = 0;
  for (size_t i = 1; i < poses.size(); ++i)
    length += blade_travel(poses[i - 1], poses[i], blade_length);
  return length;
}

std::vector<BladePose> resample_blade_path(const std::vector<BladePose>& poses, double blade_length,
                                           double spacing) {
  std::vector<BladePose> in = poses;
  for (BladePose& p : in) p.orientation.normalize();
  const double length = blade_path_length(in, blade_length);
  if (in.size() < 2 || !(length > 0) || !(spacing > 0)) return in;
  const long segments = std::max(1L, static_cast<long>(std::ceil(length / spacing - 1e-9)));
  const double h = length / static_cast<double>(segments);
  std::vector<BladePose> out;
  out.reserve(static_cast<size_t>(segments) + 1);
  out.push_back(in.front());
  size_t i = 1;   // current input segment is (i - 1, i)
  double at = 0;  // travel at in[i - 1]
  for (long k = 1; k < segments; ++k) {
    const double target = h * static_cast<double>(k);
    double d = blade_travel(in[i - 1], in[i], blade_length);
    while (at + d < target && i + 1 < in.size()) {
      at += d;
      ++i;
      d = blade_travel(in[i - 1], in[i], blade_length);
    }
    const double s = d > 0 ? std::clamp((target - at) / d, 0.0, 1.0) : 1.0;
    BladePose p;
    p.t = in[i - 1].t + s * (in[i].t - in[i - 1].t);
    p.position = in[i - 1].position + s * (in[i].position - in[i - 1].position);
    p.orientation = in[i - 1].orientation.slerp(s, in[i].orientation).normalized();
    out.push_back(p);
  }
  out.push_back(in.back());
  return out;
}

size_t straight_sweep_steps(const std::vector<BladePose>& poses, double blade_length,
                            double tolerance, double max_travel) {
  if (poses.size() < 2) return 0;
  const Vec3 edge = Vec3::UnitX() * blade_length;
  std::vector<Vec3> tip, heel;
  std::vector<double> travel = {0.0};  // from poses[0]
  for (const BladePose& p : poses) {
    tip.push_back(p.position);
    heel.push_back(p.position + p.orientation.normalized() * edge);
  }
  for (size_t i = 1; i < poses.size(); ++i)
    travel.push_back(travel.back() + blade_travel(poses[i - 1], poses[i], blade_length));
  size_t best = 1;
  for (size_t k = 2; k < poses.size() && travel[k] <= max_travel; ++k) {
    bool straight = travel[k] > 0;
    for (size_t j = 1; j < k && straight; ++j) {
      const double s = travel[j] / travel[k];
      straight = (tip[j] - (tip[0] + s * (tip[k] - tip[0]))).norm() <= tolerance &&
                 (heel[j] - (heel[0] + s * (heel[k] - heel[0]))).norm() <= tolerance;
    }
    if (!straight) break;
    best = k;
  }
  return best;
}

}  // namespace stc
