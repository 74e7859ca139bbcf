// Texture SpMV (docs/DESIGN.md section 9) on Mesa llvmpipe: Method A, Method B and the one-pass
// RowLoop layout against a double-precision CPU SpMV. EGL must work here (docs/DESIGN.md section
// 14, "Headless EGL compute"): a missing context is a failure, not a skip.
#include "common/test_matrices.hpp"
#include "gpu/egl_context.hpp"
#include "gpu/gl_reduction.hpp"
#include "gpu/gl_spmv.hpp"
#include "gpu/gl_vector.hpp"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <random>

namespace stc {
namespace gpu {
using test::elasticity_like;
using test::max_offdiag_row;
using test::random_vector;
using test::table2_matrix;
using test::with_dense_block;
namespace {

class GpuSpmv : public ::testing::TestWithParam<SpmvLayout> {
 protected:
  void SetUp() override {
    std::string why;
    ctx_ = EglContext::create(GlContextOptions{}, &why);
    ASSERT_TRUE(ctx_) << "EGL must work on llvmpipe here: " << why;
    shaders_ = std::make_unique<ShaderLibrary>(ctx_->api(), "");
    runner_ = std::make_unique<PassRunner>(*shaders_);
  }
  void TearDown() override {
    if (ctx_) ctx_->make_current();
    runner_.reset();
    shaders_.reset();
  }
  // Relative 2-norm error of the GPU product against the double CPU product.
  double spmv_error(const SparseMatrix& a, int* passes) {
    const PackedMatrix packed = pack_matrix(a, GetParam(), ctx_->max_texture_size());
    GlSpmv spmv(*runner_);
    spmv.upload(packed);
    const Vector x = random_vector(int(a.rows()), 3);
    Texture tx, ty;
    upload_vector(tx, spmv.vec_shape(), x);
    upload_vector(ty, spmv.vec_shape(), Vector::Zero(a.rows()));
    spmv.multiply(tx, ty);
    const Vector y = download_vector(ty, int(a.rows()));
    const Vector ref = a * x.cast<float>().cast<double>();
    *passes = spmv.passes();
    return (y - ref).norm() / ref.norm();
  }
  std::unique_ptr<EglContext> ctx_;
  std::unique_ptr<ShaderLibrary> shaders_;
  std::unique_ptr<PassRunner> runner_;
};

TEST_P(GpuSpmv, ElasticityLikePoisson3D) {
  const SparseMatrix a = elasticity_like(9 * 9 * 9, 9, 9);  // 2187 DOF, 20 off-diagonal/row
  int passes = 0;
  const double err = spmv_error(a, &passes);
  RecordProperty("relative_error", std::to_string(err));
  std::printf("[%s] 3D elasticity-like N=%d: rel err %.3g, %d passes (%s, %s, %s)\n",
              layout_name(GetParam()).c_str(), int(a.rows()), err, passes, ctx_->renderer().c_str(),
              ctx_->version().c_str(), ctx_->origin().c_str());
  EXPECT_LE(err, 1e-6);
  EXPECT_EQ(passes, GetParam() == SpmvLayout::MethodA   ? 20
                    : GetParam() == SpmvLayout::MethodB ? 5
                                                        : 1);
}

TEST_P(GpuSpmv, DenseInterfaceBlock) {
  // ~200 dense rows/cols (the condensed interface block K0) plus a sparse rest.
  const SparseMatrix a = with_dense_block(elasticity_like(1000, 10, 10), 200, 11);
  int passes = 0;
  const double err = spmv_error(a, &passes);
  const int max_row = max_offdiag_row(a);
  std::printf("[%s] dense block N=%d max row %d: rel err %.3g, %d passes\n",
              layout_name(GetParam()).c_str(), int(a.rows()), max_row, err, passes);
  EXPECT_LE(err, 1e-6);
  const int expected = GetParam() == SpmvLayout::MethodA   ? max_row
                       : GetParam() == SpmvLayout::MethodB ? (max_row + 3) / 4
                                                           : 1;
  EXPECT_EQ(passes, expected);
}

TEST_P(GpuSpmv, Table2MatrixHasStatedMaxRow) {
  const SparseMatrix a = table2_matrix(2190, 237);
  EXPECT_EQ(max_offdiag_row(a), 237);
  int passes = 0;
  EXPECT_LE(spmv_error(a, &passes), 1e-6);
}

// The dot products of CG (GlReduction): any fan-in, any vector length (texture shapes that are
// not multiples of the block, a single texel), against a double dot, to float32 accuracy.
TEST(GpuReduction, DotMatchesDoubleForAnyFanInAndLength) {
  std::string why;
  auto ctx = EglContext::create(GlContextOptions{}, &why);
  ASSERT_TRUE(ctx) << "EGL must work on llvmpipe here: " << why;
  {
    ShaderLibrary shaders(ctx->api(), "");
    PassRunner runner(shaders);
    for (int fan_in : {2, 3, GlReduction::kFanIn})
      for (int n : {1, 5, 1000, 20100}) {
        const TextureShape shape = vector_shape(n, 2048, ctx->max_texture_size());
        const Vector a = random_vector(n, 5), b = random_vector(n, 6);
        Texture ta, tb, target;
        upload_vector(ta, shape, a);
        upload_vector(tb, shape, b);
        target.allocate(1, 1, GL_RG32F);
        GlReduction reduction(runner, fan_in);
        reduction.configure(shape);
        reduction.dot(ta, tb, target);
        const std::vector<float> got = target.read_float(2);
        const Vector af = a.cast<float>().cast<double>(), bf = b.cast<float>().cast<double>();
        // float32 sums of n terms: relative to sum |a_i b_i| (a.b itself may nearly cancel).
        const double scale_ab = af.cwiseProduct(bf).cwiseAbs().sum();
        EXPECT_NEAR(got[0], af.dot(bf), 1e-6 * scale_ab) << "fan-in " << fan_in << ", n " << n;
        EXPECT_NEAR(got[1], af.squaredNorm(), 1e-6 * af.squaredNorm())
            << "fan-in " << fan_in << ", n " << n;
        const int side = std::max(shape.width, shape.height);
        int expected_passes = 1;  // the first pass, then one per level down to 1 x 1
        for (int m = (side + fan_in - 1) / fan_in; m > 1; m = (m + fan_in - 1) / fan_in)
          ++expected_passes;
        EXPECT_EQ(reduction.passes(), expected_passes) << "fan-in " << fan_in << ", n " << n;
      }
  }
  ctx->make_current();
}

INSTANTIATE_TEST_SUITE_P(Layouts, GpuSpmv,
                         ::testing::Values(SpmvLayout::MethodA, SpmvLayout::MethodB,
                                           SpmvLayout::RowLoop),
                         [](const ::testing::TestParamInfo<SpmvLayout>& i) {
                           return layout_name(i.param);
                         });

}  // namespace
}  // namespace gpu
}  // namespace stc
