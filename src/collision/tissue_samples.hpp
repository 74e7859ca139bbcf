// Points of the blade (its edge at one pose, or the surface it sweeps between two poses) and
// where they meet the rest tissue: what the moving operation region (simulation/
// region_follower.hpp) asks of the blade's geometry. Rest coordinates: the cut and the
// operation region live there.
#pragma once

#include "cutting/tet_grid.hpp"
#include "soft_tissue_cutting/collision/blade.hpp"
#include "soft_tissue_cutting/mesh/tet_mesh.hpp"

#include <vector>

namespace stc {

// Points along the edge, tip to heel, at most `spacing` apart (both ends included).
std::vector<Vec3> edge_samples(const BladeEdge& edge, double spacing);

// Points of the ruled surface the edge sweeps from `a` to `b` (tip to heel x start to end),
// at most `spacing` apart in both directions: every point of the surface lies within
// `spacing` of one of them.
std::vector<Vec3> sweep_samples(const BladeEdge& a, const BladeEdge& b, double spacing);

// A tet listed in `grid` whose closed rest tet holds p (boundary included, with a relative
// round-off allowance), or -1.
int tet_containing(const TetMesh& mesh, const TetGrid& grid, const Vec3& p);

// The tets listed in `grid` whose rest box overlaps the cube of half-size `reach` around p
// (a superset of the tets within `reach` of p).
std::vector<int> tets_near(const TetMesh& mesh, const TetGrid& grid, const Vec3& p, double reach);
// Whether tets_near would list any tet (without listing them).
bool any_tet_near(const TetMesh& mesh, const TetGrid& grid, const Vec3& p, double reach);

}  // namespace stc
