// Vector <-> R32F texture transfers (see gl_vector.hpp).
#include "gpu/gl_vector.hpp"

#include <epoxy/gl.h>

namespace stc {
namespace gpu {

void upload_vector(Texture& t, const TextureShape& shape, const Vector& v) {
  std::vector<float> data(shape.texels(), 0.f);
  for (Eigen::Index i = 0; i < v.size(); ++i) data[i] = float(v[i]);
  t.allocate(shape.width, shape.height, GL_R32F);
  t.upload_float(data);
}

Vector download_vector(const Texture& t, int n) {
  const std::vector<float> data = t.read_float(1);
  Vector v(n);
  for (int i = 0; i < n; ++i) v[i] = data[i];
  return v;
}

}  // namespace gpu
}  // namespace stc
