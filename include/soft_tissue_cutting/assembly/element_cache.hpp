// Per-tet element stiffness matrices, kept so that after a cut only the changed tets are
// recomputed (docs/DESIGN.md section 8: "re-assemble only the changed elements").
#pragma once

#include "soft_tissue_cutting/assembly/element_stiffness.hpp"
#include "soft_tissue_cutting/scene/scene.hpp"

#include <vector>

namespace stc {

class ElementStiffnessCache {
 public:
  ElementStiffnessCache() = default;
  ElementStiffnessCache(const TetMesh& mesh, const Material& material);
  // Copies keep room for the tets later cuts add (reserve_for_cuts).
  ElementStiffnessCache(const ElementStiffnessCache& other);
  ElementStiffnessCache& operator=(const ElementStiffnessCache& other);
  ElementStiffnessCache(ElementStiffnessCache&&) = default;
  ElementStiffnessCache& operator=(ElementStiffnessCache&&) = default;

  // The mesh changed in place: resize to its tet count and recompute the listed tets (indices
  // of replaced or appended tets). Tets not listed keep their matrices.
  void update(const TetMesh& mesh, const std::vector<int>& changed_tets);

  // Homogeneous material: every K_e is linear in E.
  void set_young_modulus(double young_modulus);

  const Mat12& operator[](int tet) const { return matrices_[static_cast<size_t>(tet)]; }
  int size() const { return static_cast<int>(matrices_.size()); }
  const Material& material() const { return material_; }

 private:
  void reserve_for_cuts(size_t tets);
  Material material_;
  std::vector<Mat12> matrices_;
};

}  // namespace stc
