// GL backend of LinearSolver: GPU float CG + CPU double iterative refinement (see
// gl_solver.hpp). float32's true-residual floor is ~1e-7 relative (docs/DESIGN.md section 14), so
// each refinement step gains roughly that factor (less for ill-conditioned A) until the requested
// tolerance.
#include "soft_tissue_cutting/gpu/gl_solver.hpp"

#include "soft_tissue_cutting/gpu/egl_context.hpp"
#include "soft_tissue_cutting/gpu/gl_cg.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace stc {
namespace {

class GlSolver final : public LinearSolver {
 public:
  GlSolver(std::unique_ptr<gpu::EglContext> ctx, const GlSolverOptions& options)
      : options_(options), ctx_(std::move(ctx)) {
    shaders_ = std::make_unique<gpu::ShaderLibrary>(ctx_->api());
    runner_ = std::make_unique<gpu::PassRunner>(*shaders_);
    spmv_ = std::make_unique<gpu::GlSpmv>(*runner_);
    cg_ = std::make_unique<gpu::GlCg>(*runner_, *spmv_);
    // Compile every program now: a driver that cannot build them fails the factory (with
    // the compiler log) instead of the first solve, and timing never includes compilation.
    for (const char* f : {"spmv_method_a.frag.glsl", "spmv_method_b.frag.glsl",
                          "spmv_row_loop.frag.glsl", "dot_first.frag.glsl", "reduce_sum.frag.glsl",
                          "cg_init.frag.glsl", "cg_alpha.frag.glsl", "cg_beta.frag.glsl",
                          "cg_update_xrz.frag.glsl", "cg_update_p.frag.glsl"})
      shaders_->program(f);
  }
  ~GlSolver() override {
    ctx_->make_current();  // GL objects are deleted with the context current
    cg_.reset();
    spmv_.reset();
    runner_.reset();
    shaders_.reset();
  }

  std::string backend() const override { return "gl"; }
  std::string renderer() const override { return ctx_->renderer(); }

  void set_matrix(const SparseMatrix& a) override {
    ctx_->make_current();
    a_ = a;
    diagonal_ = a_.diagonal();
    // Textures of unchanged size are patched in place (Texture::allocate keeps them).
    spmv_->upload(gpu::pack_matrix(a_, options_.layout, ctx_->max_texture_size()));
    mask_.resize(0);  // force a mask upload on the next solve
  }

  CgResult solve(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                 const CgSettings& settings) override {
    ctx_->make_current();
    const Eigen::Index n = a_.rows();
    CgResult result;
    if (b.size() != n) throw std::invalid_argument("gl solver: b has the wrong size");
    if (!constrained.empty() && Eigen::Index(constrained.size()) != n)
      throw std::invalid_argument("gl solver: constrained has the wrong size");
    if (x.size() != n) x = Vector::Zero(n);
    Vector mask = Vector::Ones(n);
    if (!constrained.empty())
      for (Eigen::Index i = 0; i < n; ++i)
        if (constrained[std::size_t(i)]) mask[i] = 0;
    const Vector keep = Vector::Ones(n) - mask;

    // Denominator: the reduced right-hand side b_f - A_fc x_c (as the CPU backend).
    const double rhs_norm = (b - a_ * x.cwiseProduct(keep)).cwiseProduct(mask).norm();
    if (n == 0 || rhs_norm == 0) {
      x = x.cwiseProduct(keep);
      result.converged = true;
      return result;
    }
    if (mask_.size() != n || mask_ != mask) {
      cg_->set_mask(mask, diagonal_);
      mask_ = mask;
    }

    Vector r = (b - a_ * x).cwiseProduct(mask);
    result.residual = r.norm() / rhs_norm;
    for (int step = 0; step < options_.max_refinements; ++step) {
      if (result.residual <= settings.tolerance || result.iterations >= settings.max_iterations) break;
      // Scale to unit norm: float keeps its full relative precision whatever |r| is.
      const double scale = r.norm();
      cg_->start(r / scale);
      // The float CG need not go below what the tolerance asks of this step.
      const double target = std::max(options_.inner_reduction,
                                     0.5 * settings.tolerance * rhs_norm / scale);
      double best = 1.0;
      int stalled = 0;
      while (result.iterations < settings.max_iterations) {
        const int k = std::min(options_.check_every, settings.max_iterations - result.iterations);
        cg_->iterate(k);
        result.iterations += k;
        const double rel = std::sqrt(cg_->residual_norm2());
        if (!std::isfinite(rel) || rel <= target) break;
        if (rel < 0.9 * best) {
          best = rel;
          stalled = 0;
        } else if (++stalled >= options_.stall_checks) {
          break;
        }
      }
      const Vector d = cg_->solution();
      if (!d.allFinite()) break;
      const Vector x_new = x + scale * d.cwiseProduct(mask);
      const Vector r_new = (b - a_ * x_new).cwiseProduct(mask);
      const double res_new = r_new.norm() / rhs_norm;
      if (!(res_new < result.residual)) break;  // refinement no longer helps: keep the best x
      x = x_new;
      r = r_new;
      result.residual = res_new;
    }
    result.converged = result.residual <= settings.tolerance;
    return result;
  }

 private:
  GlSolverOptions options_;
  std::unique_ptr<gpu::EglContext> ctx_;
  std::unique_ptr<gpu::ShaderLibrary> shaders_;
  std::unique_ptr<gpu::PassRunner> runner_;
  std::unique_ptr<gpu::GlSpmv> spmv_;
  std::unique_ptr<gpu::GlCg> cg_;
  SparseMatrix a_;
  Vector diagonal_, mask_;
};

}  // namespace

std::unique_ptr<LinearSolver> make_gl_solver(std::string* why_not) {
  return make_gl_solver(GlSolverOptions{}, why_not);
}

std::unique_ptr<LinearSolver> make_gl_solver(const GlSolverOptions& options, std::string* why_not) {
  std::unique_ptr<gpu::EglContext> ctx = gpu::EglContext::create(why_not);
  if (!ctx) return nullptr;
  try {
    auto solver = std::make_unique<GlSolver>(std::move(ctx), options);
    return solver;
  } catch (const std::exception& e) {
    if (why_not) *why_not = std::string("GL backend setup failed: ") + e.what();
    return nullptr;
  }
}

}  // namespace stc
