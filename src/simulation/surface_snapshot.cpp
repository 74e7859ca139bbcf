#include "soft_tissue_cutting/simulation/surface_snapshot.hpp"

namespace stc {

DeformedSurface SurfaceSnapshot::compute() {
  displacement.recover();
  DeformedSurface s;
  s.positions.resize(rest.size());
  s.displacement.resize(rest.size());
  for (size_t i = 0; i < rest.size(); ++i) {
    const Vec3 ui = displacement.u.segment<3>(3 * static_cast<long>(i));
    s.positions[i] = rest[i] + ui;
    s.displacement[i] = ui.norm();
  }
  s.triangles = triangles;
  return s;
}

}  // namespace stc
