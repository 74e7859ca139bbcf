// GL backend of LinearSolver: GPU float CG + CPU double iterative refinement (see
// gl_solver.hpp). A float32 CG's true residual bottoms out near eps_float * cond(S A S)
// relative, so each refinement step gains at most that factor; the steps repeat until the
// requested tolerance, or until they stop gaining (cond beyond ~1e7) and the CPU takes over.
#include "soft_tissue_cutting/gpu/gl_solver.hpp"

#include "gpu/egl_context.hpp"
#include "gpu/gl_cg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace stc {
namespace {

class GlSolver final : public LinearSolver {
 public:
  GlSolver(std::unique_ptr<gpu::EglContext> ctx, const GlSolverOptions& options)
      : options_(options), ctx_(std::move(ctx)) {
    shaders_ = std::make_unique<gpu::ShaderLibrary>(ctx_->api(), options.context.shader_dir);
    runner_ = std::make_unique<gpu::PassRunner>(*shaders_);
    spmv_ = std::make_unique<gpu::GlSpmv>(*runner_);
    cg_ = std::make_unique<gpu::GlCg>(*runner_, *spmv_);
    // Compile every program now: a driver that cannot build them fails the factory (with
    // the compiler log) instead of the first solve, and timing never includes compilation.
    for (const char* f :
         {"spmv_method_a.frag.glsl", "spmv_method_b.frag.glsl", "spmv_row_loop.frag.glsl",
          "dot_first.frag.glsl", "reduce_sum.frag.glsl", "cg_init.frag.glsl", "cg_alpha.frag.glsl",
          "cg_beta.frag.glsl", "cg_update_xrz.frag.glsl", "cg_update_p.frag.glsl"})
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
  std::string preconditioner() const override { return "jacobi"; }

  void set_matrix(const SparseMatrix& a) override { set_matrix(a, {}); }

  // Jacobi-CG needs no factor; `held` goes to the CPU fallback's Cholesky preconditioner.
  void set_matrix(const SparseMatrix& a, const std::vector<std::uint8_t>& held) override {
    held_ = held;
    ctx_->make_current();
    a_ = a;
    cpu_has_matrix_ = false;
    unusable_.clear();
    // Symmetric Jacobi scaling S A S, S = diag(A)^-1/2: unit diagonal, every off-diagonal
    // entry within [-1, 1] for SPD A, so float32 holds the matrix whatever its units. CG on
    // S A S is Jacobi-preconditioned CG on A. A non-positive diagonal (not SPD) keeps s = 1.
    scaling_ = Vector::Ones(a_.rows());
    for (Eigen::Index i = 0; i < a_.rows(); ++i) {
      const double d = a_.coeff(i, i);
      if (d > 0 && std::isfinite(d)) scaling_[i] = 1.0 / std::sqrt(d);
    }
    const SparseMatrix scaled = scaling_.asDiagonal() * a_ * scaling_.asDiagonal();
    scaled_diagonal_ = scaled.diagonal();
    try {
      // Textures of unchanged size are patched in place (Texture::allocate keeps them).
      const int limit =
          options_.max_texture_size > 0 ? options_.max_texture_size : ctx_->max_texture_size();
      spmv_->upload(gpu::pack_matrix(scaled, options_.layout, limit));
    } catch (const std::exception& e) {
      unusable_ = e.what();  // e.g. beyond the texture size limit: solves go to the CPU
    }
    mask_.resize(0);  // force a mask upload on the next solve
  }

  CgResult solve(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                 const CgSettings& settings) override {
    ctx_->make_current();
    const Eigen::Index n = a_.rows();
    CgResult result;
    result.solved_by = "gl";
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
    if (!std::isfinite(rhs_norm)) throw std::invalid_argument("gl solver: b is not finite");
    if (!unusable_.empty()) return fall_back(b, x, constrained, settings, result, unusable_);
    if (mask_.size() != n || mask_ != mask) {
      cg_->set_mask(mask, scaled_diagonal_);
      mask_ = mask;
    }
    const long free_dofs = long(mask.sum());
    const long inner_cap =
        std::max<long>(options_.inner_min_iterations, long(options_.inner_dofs_factor) * free_dofs);

    Vector r = (b - a_ * x).cwiseProduct(mask);
    result.residual = r.norm() / rhs_norm;
    std::string float_limit;  // set when float32 cannot get to the tolerance
    int poor = 0;
    for (int step = 0;; ++step) {
      if (result.residual <= settings.tolerance) break;
      if (result.iterations >= settings.max_iterations) break;
      if (step >= options_.max_refinements) {
        float_limit = std::to_string(step) + " refinement steps left it at relative residual " +
                      format(result.residual);
        break;
      }
      // Solve (S A S) y = S r / |S r| in float, then d = |S r| S y: unit-norm right-hand side,
      // so float keeps its full relative precision whatever |r| is (1e-9 N or 1e3 N).
      const Vector rs = scaling_.cwiseProduct(r);
      const double scale = rs.norm();
      cg_->start(rs / scale);
      // The float CG need not go below what the tolerance asks of this step.
      const double target =
          std::max(options_.inner_reduction, 0.5 * settings.tolerance * rhs_norm / r.norm());
      const long budget =
          std::min<long>(inner_cap, long(settings.max_iterations) - result.iterations);
      long done = 0;
      bool reached = false;
      while (done < budget) {
        const int k = int(std::min<long>(options_.check_every, budget - done));
        cg_->iterate(k);
        done += k;
        // The only scalar read back; CG's residual is not monotone (long plateaus on the
        // condensed surface's dense rows), so only the target or the budget ends the step.
        const double rel = std::sqrt(cg_->residual_norm2());
        if (!std::isfinite(rel)) break;
        if (rel <= target) {
          reached = true;
          break;
        }
      }
      result.iterations += int(done);
      const Vector d = cg_->solution();
      if (!d.allFinite()) {
        float_limit = "the float32 CG produced non-finite values";
        break;
      }
      const Vector x_new = x + scale * scaling_.cwiseProduct(d).cwiseProduct(mask);
      const Vector r_new = (b - a_ * x_new).cwiseProduct(mask);
      const double res_new = r_new.norm() / rhs_norm;
      const double before = result.residual;
      if (res_new < before) {  // keep the best x
        x = x_new;
        r = r_new;
        result.residual = res_new;
      }
      if (res_new <= 0.5 * before) {
        poor = 0;
        continue;
      }
      // Cut short by max_iterations: not float's fault, the loop ends at the cap.
      if (!reached && result.iterations >= settings.max_iterations) continue;
      if (++poor >= options_.poor_steps) {
        float_limit =
            "float32 refinement stopped gaining at relative residual " + format(result.residual);
        break;
      }
    }
    result.converged = result.residual <= settings.tolerance;
    if (result.converged) return result;
    if (!float_limit.empty()) {
      if (options_.cpu_fallback) return fall_back(b, x, constrained, settings, result, float_limit);
      result.message = float_limit + " (tolerance " + format(settings.tolerance) + ")";
    } else {
      result.message = iteration_cap_message(result, settings);
    }
    return result;
  }

 private:
  GlSolverOptions options_;
  std::unique_ptr<gpu::EglContext> ctx_;
  std::unique_ptr<gpu::ShaderLibrary> shaders_;
  std::unique_ptr<gpu::PassRunner> runner_;
  std::unique_ptr<gpu::GlSpmv> spmv_;
  std::unique_ptr<gpu::GlCg> cg_;
  static std::string format(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
  }

  // Finishes the solve on the CPU from the best x so far with the iterations left.
  CgResult fall_back(const Vector& b, Vector& x, const std::vector<std::uint8_t>& constrained,
                     const CgSettings& settings, const CgResult& gl, const std::string& why) {
    if (!cpu_) cpu_ = make_cpu_solver();
    if (!cpu_has_matrix_) {
      cpu_->set_matrix(a_, held_);
      cpu_has_matrix_ = true;
    }
    CgSettings rest = settings;
    rest.max_iterations = std::max(0, settings.max_iterations - gl.iterations);
    CgResult r = cpu_->solve(b, x, constrained, rest);
    r.iterations += gl.iterations;
    r.solved_by = "cpu";
    r.fallback_reason = "gl fell back to the cpu: " + why;
    if (!r.converged && r.iterations >= settings.max_iterations)
      r.message = iteration_cap_message(r, settings);
    return r;
  }

  SparseMatrix a_;
  Vector scaling_, scaled_diagonal_, mask_;
  std::string unusable_;  // why the current matrix cannot go to the GPU (empty: it can)
  std::unique_ptr<LinearSolver> cpu_;  // the fallback, made and factored only when needed
  bool cpu_has_matrix_ = false;
  std::vector<std::uint8_t> held_;  // per DOF, for the CPU fallback (set_matrix)
};

}  // namespace

std::unique_ptr<LinearSolver> make_gl_solver(std::string* why_not) {
  return make_gl_solver(GlSolverOptions{}, why_not);
}

std::unique_ptr<LinearSolver> make_gl_solver(const GlSolverOptions& options, std::string* why_not) {
  std::unique_ptr<gpu::EglContext> ctx = gpu::EglContext::create(options.context, why_not);
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
