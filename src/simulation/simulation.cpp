#include "soft_tissue_cutting/simulation/simulation.hpp"

#include <chrono>
#include <cstdio>
#include <functional>
#include <sstream>
#include <stdexcept>

namespace stc {

struct Simulation::Impl {
  Scene initial;
  SimulationOptions options;
  TetMesh mesh;
  Eigen::VectorXd u;
  StepStats last;
  std::uint64_t steps = 0;
  std::uint64_t surface_version = 0;
  bool cutting_enabled = true;

  void start() {
    mesh = initial.mesh;
    u = Eigen::VectorXd::Zero(3 * mesh.num_nodes());
    last = StepStats{};
    steps = 0;
    ++surface_version;
  }
};

Simulation::Simulation(Scene scene, SimulationOptions options) : impl_(new Impl) {
  impl_->initial = std::move(scene);
  impl_->options = std::move(options);
  impl_->start();
}

Simulation::~Simulation() = default;

StepStats Simulation::step(const std::optional<BladePose>&) {
  StepStats s;
  s.step = ++impl_->steps;
  impl_->last = s;
  return s;
}

CutOutcome Simulation::cut_along(const std::vector<BladePose>&) {
  return CutOutcome{false, "cutting not available yet", 0, 0, 0};
}

void Simulation::reset() { impl_->start(); }
void Simulation::set_cutting_enabled(bool enabled) { impl_->cutting_enabled = enabled; }
bool Simulation::cutting_enabled() const { return impl_->cutting_enabled; }
void Simulation::set_cut_pressure(double newtons) { impl_->initial.scalpel.cut_pressure = newtons; }
void Simulation::set_young_modulus(double pascal) { impl_->initial.material.young_modulus = pascal; }
const Scene& Simulation::scene() const { return impl_->initial; }
const TetMesh& Simulation::mesh() const { return impl_->mesh; }

DeformedSurface Simulation::surface() const {
  DeformedSurface s;
  const TetMesh& m = impl_->mesh;
  s.positions.resize(m.nodes.size());
  s.displacement.resize(m.nodes.size());
  for (int i = 0; i < m.num_nodes(); ++i) {
    const Vec3 u = impl_->u.segment<3>(3 * i);
    s.positions[i] = m.nodes[i] + u;
    s.displacement[i] = u.norm();
  }
  s.triangles = extract_boundary_surface(m).triangles;
  return s;
}

std::uint64_t Simulation::surface_version() const { return impl_->surface_version; }

ModelCounts Simulation::counts() const {
  ModelCounts c;
  c.nodes = impl_->mesh.num_nodes();
  c.tets = impl_->mesh.num_tets();
  c.volume_initial = total_volume(impl_->initial.mesh);
  c.volume_final = total_volume(impl_->mesh);
  return c;
}

const StepStats& Simulation::last_stats() const { return impl_->last; }
std::string Simulation::backend() const { return "cpu"; }
std::string Simulation::renderer() const { return ""; }
std::string Simulation::backend_note() const { return ""; }

std::vector<std::uint8_t> Simulation::tet_regions() const {
  std::vector<std::uint8_t> r(impl_->mesh.tets.size());
  for (size_t t = 0; t < r.size(); ++t) {
    Vec3 c = Vec3::Zero();
    for (int v : impl_->mesh.tets[t]) c += impl_->mesh.nodes[v] / 4.0;
    r[t] = impl_->initial.operation_region.contains(c);
  }
  return r;
}

std::vector<BladePose> Simulation::blade_path() const { return {}; }
Eigen::VectorXd Simulation::full_displacement() { return impl_->u; }
void Simulation::write_vtk(const std::string&) { throw std::runtime_error("write_vtk: not yet"); }
void Simulation::write_stats_json(const std::string&, double) {
  throw std::runtime_error("write_stats_json: not yet");
}
std::string Simulation::stats_json(double) { return "{}"; }

std::string Simulation::mesh_hash() const {
  // FNV-1a over the topology and the rest positions' bits: equal meshes, equal hashes.
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  };
  for (const Vec3& x : impl_->mesh.nodes) mix(x.data(), 3 * sizeof(double));
  for (const Tet& t : impl_->mesh.tets) mix(t.data(), 4 * sizeof(int));
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace stc
