// GPU texture SpMV and whole-CG benchmarks (docs/DESIGN.md section 9; the paper's Table 2 in
// section 13). Rows of Table 2 are synthesized: SPD matrices with the same DOF and the same
// longest row (off-diagonal non-zeros 188..237, reached by a dense interface block), run
// with Method A, Method B, our one-pass RowLoop layout, and the CPU (Eigen CSR, double).
// Then a scaling run of whole CG iterations at 10k, 100k, 1M DOF.
//
// The device is named in the context ("gl_renderer") and in each GPU label. On Mesa
// llvmpipe (software rasterizer on the CPU) the numbers say nothing about real GPU speed,
// only about pass overheads; docs/DESIGN.md section 14: llvmpipe is for correctness.
// Times are per SpMV / per CG iteration; use --benchmark_repetitions for medians.
#include "common/test_matrices.hpp"
#include "gpu/egl_context.hpp"
#include "gpu/gl_cg.hpp"
#include "gpu/gl_reduction.hpp"
#include "gpu/gl_vector.hpp"

#include <benchmark/benchmark.h>
#include <epoxy/gl.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>

namespace stc {
namespace gpu {
using test::elasticity_like;
using test::random_vector;
using test::table2_matrix;
namespace {

struct Gl {
  std::unique_ptr<EglContext> ctx;
  std::unique_ptr<ShaderLibrary> shaders;
  std::unique_ptr<PassRunner> runner;
  std::string why_not;
};

Gl& gl() {
  static Gl g = [] {
    Gl out;
    out.ctx = EglContext::create(GlContextOptions{}, &out.why_not);
    if (out.ctx) {
      out.shaders = std::make_unique<ShaderLibrary>(out.ctx->api(), "");
      out.runner = std::make_unique<PassRunner>(*out.shaders);
    }
    return out;
  }();
  return g;
}

// Matrices are built once per size and shared by all layouts.
const SparseMatrix& table2(int dof, int max_row) {
  static std::map<std::pair<int, int>, SparseMatrix> cache;
  auto it = cache.find({dof, max_row});
  if (it == cache.end())
    it = cache.emplace(std::make_pair(dof, max_row), table2_matrix(dof, max_row)).first;
  return it->second;
}

const SparseMatrix& scaling(int dof) {
  static std::map<int, SparseMatrix> cache;
  auto it = cache.find(dof);
  if (it == cache.end()) {
    const int nodes = dof / 3;
    const int side = int(std::ceil(std::cbrt(double(nodes))));
    it = cache.emplace(dof, elasticity_like(nodes, side, side)).first;
  }
  return it->second;
}

// Untimed runs before a benchmark's timed ones (the first is a shader compile on any driver).
constexpr int kWarmUp = 4;

// llvmpipe renders on the CPU: the 1M-row runs take seconds there and get fixed iteration
// counts; a hardware GPU runs for a minimum time like any other benchmark.
bool software_renderer() {
  return gl().ctx && gl().ctx->renderer().find("llvmpipe") != std::string::npos;
}

std::string short_renderer() {
  const std::string& r = gl().ctx->renderer();
  return r.substr(0, r.find(" ("));
}

void gpu_spmv(benchmark::State& state, const SparseMatrix& a, SpmvLayout layout) {
  Gl& g = gl();
  g.ctx->make_current();
  GlSpmv spmv(*g.runner);
  spmv.upload(pack_matrix(a, layout, g.ctx->max_texture_size()));
  Texture x, y;
  upload_vector(x, spmv.vec_shape(), random_vector(a.rows(), 1));
  upload_vector(y, spmv.vec_shape(), Vector::Zero(a.rows()));
  // Warm-up: shaders compile lazily, and a real GPU's driver finishes freshly uploaded textures
  // in the first draws (on an H200 the first 1M-row products took twice as long).
  for (int i = 0; i < kWarmUp; ++i) spmv.multiply(x, y);
  g.runner->finish();
  for (auto _ : state) {
    spmv.multiply(x, y);
    g.runner->finish();
  }
  state.counters["dof"] = double(a.rows());
  state.counters["max_row"] = spmv.max_row();
  state.counters["passes"] = spmv.passes();
  state.SetLabel(layout_name(layout) + " on " + short_renderer());
}

// Whole CG on the GPU: one benchmark iteration = k CG iterations + the one ||r||^2 read-back
// (what the solver does); the reported (manual) time is divided by k -> per CG iteration.
void gpu_cg(benchmark::State& state, const SparseMatrix& a, SpmvLayout layout, int k) {
  Gl& g = gl();
  g.ctx->make_current();
  GlSpmv spmv(*g.runner);
  spmv.upload(pack_matrix(a, layout, g.ctx->max_texture_size()));
  GlCg cg(*g.runner, spmv);
  cg.set_mask(Vector::Ones(a.rows()), a.diagonal());
  Vector r0 = random_vector(a.rows(), 2);
  r0 /= r0.norm();
  cg.start(r0);
  cg.iterate(kWarmUp);  // warm-up, as in gpu_spmv
  cg.residual_norm2();
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    cg.iterate(k);
    const double rr = cg.residual_norm2();
    const auto t1 = std::chrono::steady_clock::now();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count() / k);
    if (!(rr > 1e-8)) cg.start(r0);  // converged: restart, so no timing on a zero residual
  }
  state.counters["dof"] = double(a.rows());
  state.counters["passes_per_iter"] = cg.passes_per_iteration();
  state.counters["spmv_passes"] = spmv.passes();
  state.SetLabel(layout_name(layout) + " on " + short_renderer());
}

// One dot product (the CG's reduction, GlReduction::dot) into a 1x1 texture; finish() waits
// for it, as CG's read-back of r.r does.
void gpu_dot(benchmark::State& state, int n, int fan_in = GlReduction::kFanIn) {
  Gl& g = gl();
  g.ctx->make_current();
  const TextureShape shape = vector_shape(n, 2048, g.ctx->max_texture_size());
  GlReduction reduction(*g.runner, fan_in);
  reduction.configure(shape);
  Texture a, b, target;
  upload_vector(a, shape, random_vector(n, 1));
  upload_vector(b, shape, random_vector(n, 2));
  target.allocate(1, 1, GL_RG32F);
  for (int i = 0; i < kWarmUp; ++i) reduction.dot(a, b, target);  // warm-up, as in gpu_spmv
  g.runner->finish();
  for (auto _ : state) {
    reduction.dot(a, b, target);
    g.runner->finish();
  }
  state.counters["n"] = double(n);
  state.counters["passes"] = reduction.passes();
  state.SetLabel("reduction on " + short_renderer());
}

void cpu_spmv(benchmark::State& state, const SparseMatrix& a) {
  const Vector x = random_vector(a.rows(), 1);
  Vector y(a.rows());
  for (auto _ : state) {
    y.noalias() = a * x;
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["dof"] = double(a.rows());
  state.SetLabel("cpu csr double");
}

// One Jacobi-PCG iteration in double on the CPU (SpMV, 2 dots, 3 vector updates).
void cpu_cg(benchmark::State& state, const SparseMatrix& a) {
  const Vector minv = a.diagonal().cwiseInverse();
  const Vector b = random_vector(a.rows(), 2);
  Vector x = Vector::Zero(a.rows()), r = b, z = minv.cwiseProduct(r), p = z, q(a.rows());
  double rz = r.dot(z);
  for (auto _ : state) {
    q.noalias() = a * p;
    const double alpha = rz / p.dot(q);
    x.noalias() += alpha * p;
    r.noalias() -= alpha * q;
    z = minv.cwiseProduct(r);
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
    if (!(rz > 1e-20)) {  // converged: restart
      x.setZero();
      r = b;
      z = minv.cwiseProduct(r);
      p = z;
      rz = r.dot(z);
    }
    benchmark::DoNotOptimize(x.data());
  }
  state.counters["dof"] = double(a.rows());
  state.SetLabel("cpu jacobi-pcg double");
}

const int kTable2[7][2] = {{456, 188},  {960, 188},  {1137, 188}, {1602, 188},
                           {1854, 190}, {2100, 231}, {2190, 237}};
const SpmvLayout kLayouts[3] = {SpmvLayout::MethodA, SpmvLayout::MethodB, SpmvLayout::RowLoop};

// Registration at static-initialisation time (benchmark_main provides main): the GL context is
// made here so its renderer can go into the benchmark context.
int register_all() {
  Gl& g = gl();
  benchmark::AddCustomContext("gl_renderer", g.ctx ? g.ctx->renderer() + " / " + g.ctx->version() +
                                                         " via " + g.ctx->origin()
                                                   : "unavailable: " + g.why_not);
  for (const auto& row : kTable2) {
    const int dof = row[0], max_row = row[1];
    const std::string tag = "/dof:" + std::to_string(dof) + "/max_row:" + std::to_string(max_row);
    for (SpmvLayout l : kLayouts) {
      if (!g.ctx) break;
      benchmark::RegisterBenchmark(
          ("Table2_SpMV/" + layout_name(l) + tag).c_str(),
          [=](benchmark::State& s) { gpu_spmv(s, table2(dof, max_row), l); })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.05);
      benchmark::RegisterBenchmark(
          ("Table2_CgIter/" + layout_name(l) + tag).c_str(),
          [=](benchmark::State& s) { gpu_cg(s, table2(dof, max_row), l, 8); })
          ->Unit(benchmark::kMillisecond)
          ->UseManualTime()
          ->MinTime(0.05);
    }
    benchmark::RegisterBenchmark(("Table2_SpMV/cpu" + tag).c_str(),
                                 [=](benchmark::State& s) { cpu_spmv(s, table2(dof, max_row)); })
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.05);
    benchmark::RegisterBenchmark(("Table2_CgIter/cpu" + tag).c_str(),
                                 [=](benchmark::State& s) { cpu_cg(s, table2(dof, max_row)); })
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.05);
  }
  // Scaling of whole CG iterations (3D elasticity-like, 20 off-diagonal non-zeros per row).
  // On llvmpipe, fixed iteration counts (and 4 instead of 8 CG iterations per read-back at 1M)
  // keep the 1M runs to seconds.
  for (int dof : {10002, 100002, 1000002}) {
    const std::string tag = "/dof:" + std::to_string(dof);
    const int bench_iters = !software_renderer() ? 0
                            : dof > 500000       ? 1
                            : dof > 50000        ? 4
                                                 : 0;  // 0: automatic
    // The parts of one CG iteration: the SpMV and one of its two dot products.
    if (g.ctx) {
      benchmark::RegisterBenchmark(
          ("Scaling_SpMV/row_loop" + tag).c_str(),
          [=](benchmark::State& s) { gpu_spmv(s, scaling(dof), SpmvLayout::RowLoop); })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.05);
      // Same-run comparison with the first design's 2 x 2 reduction passes.
      for (int fan_in : {2, 4})
        benchmark::RegisterBenchmark(("Scaling_Dot/fan_in:" + std::to_string(fan_in) + tag).c_str(),
                                     [=](benchmark::State& s) { gpu_dot(s, dof, fan_in); })
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.05);
    }
    for (SpmvLayout l : kLayouts) {
      if (!g.ctx) break;
      auto* b = benchmark::RegisterBenchmark(
          ("Scaling_CgIter/" + layout_name(l) + tag).c_str(),
          [=](benchmark::State& s) { gpu_cg(s, scaling(dof), l, dof > 500000 ? 4 : 8); });
      b->Unit(benchmark::kMillisecond)->UseManualTime();
      if (bench_iters)
        b->Iterations(bench_iters);
      else
        b->MinTime(0.05);
    }
    auto* b = benchmark::RegisterBenchmark(("Scaling_CgIter/cpu" + tag).c_str(),
                                           [=](benchmark::State& s) { cpu_cg(s, scaling(dof)); });
    b->Unit(benchmark::kMillisecond);
    if (bench_iters)
      b->Iterations(8 * bench_iters);
    else
      b->MinTime(0.05);
  }
  return 0;
}

const int registered = register_all();

}  // namespace
}  // namespace gpu
}  // namespace stc
