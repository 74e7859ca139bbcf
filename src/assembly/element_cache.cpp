#include "soft_tissue_cutting/assembly/element_cache.hpp"

namespace stc {
namespace {

Mat12 stiffness_of(const TetMesh& mesh, int t, const Material& m) {
  const Tet& e = mesh.tets[static_cast<size_t>(t)];
  return element_stiffness(mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]], mesh.nodes[e[3]],
                           m.young_modulus, m.poisson_ratio);
}

}  // namespace

ElementStiffnessCache::ElementStiffnessCache(const TetMesh& mesh, const Material& material)
    : material_(material) {
  reserve_for_cuts(mesh.tets.size());
  matrices_.resize(mesh.tets.size());
  for (int t = 0; t < mesh.num_tets(); ++t) matrices_[t] = stiffness_of(mesh, t, material_);
}

ElementStiffnessCache::ElementStiffnessCache(const ElementStiffnessCache& other)
    : material_(other.material_) {
  reserve_for_cuts(other.matrices_.size());  // a region move's model is cut next
  matrices_ = other.matrices_;
}

ElementStiffnessCache& ElementStiffnessCache::operator=(const ElementStiffnessCache& other) {
  if (this != &other) {
    material_ = other.material_;
    reserve_for_cuts(other.matrices_.size());
    matrices_ = other.matrices_;
  }
  return *this;
}

void ElementStiffnessCache::reserve_for_cuts(size_t tets) {
  // Room for the tets cuts add (a 3 cm cut adds ~1k): growing past the capacity copies every
  // matrix (1.2 kB per tet, 82 MB on the organ liver) inside a cutting step (the organ's
  // slowest cutting step 65 -> 28 ms) and holds the old and the new array at once.
  matrices_.reserve(tets + tets / 8 + 1024);
}

void ElementStiffnessCache::update(const TetMesh& mesh, const std::vector<int>& changed_tets) {
  matrices_.resize(mesh.tets.size());
  for (int t : changed_tets) matrices_[static_cast<size_t>(t)] = stiffness_of(mesh, t, material_);
}

void ElementStiffnessCache::set_young_modulus(double young_modulus) {
  const double s = young_modulus / material_.young_modulus;
  for (Mat12& k : matrices_) k *= s;
  material_.young_modulus = young_modulus;
}

}  // namespace stc
