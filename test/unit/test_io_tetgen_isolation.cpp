// TetGen runs in a forked child (src/io/isolated_child.*): surfaces that make TetGen 1.5 fail,
// abort (failed assertions) or crash must end as ONE MeshError line naming the file, and the
// test process itself must survive. Also `tissue_solve` on such a surface: exit status 1 and a
// one-line message, never a signal.
#include "../../src/io/isolated_child.hpp"
#include "soft_tissue_cutting/io/mesh_error.hpp"
#include "soft_tissue_cutting/io/mesh_reader.hpp"
#include "test_io_util.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <csignal>
#include <cstdlib>
#include <fstream>
#include <string>

namespace stc {
namespace {

const std::string kBad = std::string(TISSUE_TEST_DATA_DIR) + "/bad_surfaces/";

// The MeshError of read_mesh(path), or "" if it succeeded.
std::string read_error(const std::string& path) {
  try {
    const TetMesh mesh = read_mesh(path);
    ADD_FAILURE() << path << " was read (" << mesh.num_tets() << " tets), expected an error";
  } catch (const MeshError& e) {
    return e.what();
  }
  return "";
}

void expect_one_line_naming(const std::string& message, const std::string& path,
                            const std::string& cause) {
  EXPECT_EQ(message.rfind(path + ":", 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find(cause), std::string::npos) << message;
}

struct BadSurface {
  const char* file;
  const char* cause;  // part of the expected message
};

class TetgenBadSurface : public ::testing::TestWithParam<BadSurface> {};

TEST_P(TetgenBadSurface, OneLineErrorNamingTheFile) {
  const std::string path = kBad + GetParam().file;
  expect_one_line_naming(read_error(path), path, GetParam().cause);
}

INSTANTIATE_TEST_SUITE_P(
    Surfaces, TetgenBadSurface,
    ::testing::Values(
        // closed, but two cubes overlap: TetGen -d finds the intersecting triangles
        BadSurface{"self_intersecting.obj", "the surface intersects itself (12 intersecting"},
        // refused before TetGen
        BadSurface{"open_box.obj", "surface is not closed"},
        // TetGen 1.5 aborts on these (failed assertions): the child dies with SIGABRT
        BadSurface{"flat_cube.obj", "TetGen crashed (signal 6, SIGABRT): Assertion `maxz > 0'"},
        BadSurface{"huge_cube.obj", "TetGen crashed (signal 6, SIGABRT): Assertion"}),
    [](const auto& info) {
      std::string name = info.param.file;
      return name.substr(0, name.find('.'));
    });

// The isolation itself, independent of what TetGen does with a given input.
TEST(IsolatedChild, ReturnsTheChildsBytes) {
  const std::string big(1 << 20, 'x');  // more than a pipe holds
  EXPECT_EQ(io::run_isolated(
                "f.obj", "job", [&] { return big + "end"; }, 60.0),
            big + "end");
}

TEST(IsolatedChild, SignalBecomesOneLineNamingTheFile) {
  try {
    io::run_isolated(
        "f.obj", "TetGen",
        []() -> std::string {
          std::raise(SIGSEGV);
          return "";
        },
        60.0);
    FAIL() << "no error";
  } catch (const MeshError& e) {
    expect_one_line_naming(e.what(), "f.obj", "TetGen crashed (signal 11, SIGSEGV)");
  }
}

TEST(IsolatedChild, ExceptionMessageComesBack) {
  try {
    io::run_isolated(
        "f.obj", "TetGen", []() -> std::string { throw 3; }, 60.0);
    FAIL() << "no error";
  } catch (const MeshError& e) {
    EXPECT_STREQ(e.what(), "f.obj: TetGen failed: error code 3");
  }
}

TEST(IsolatedChild, TimeoutKillsTheChild) {
  try {
    io::run_isolated(
        "f.obj", "TetGen",
        []() -> std::string {
          for (;;) pause();
        },
        0.3);
    FAIL() << "no error";
  } catch (const MeshError& e) {
    EXPECT_STREQ(e.what(), "f.obj: TetGen did not finish within 0.3 s (stopped)");
  }
}

#ifdef TISSUE_SOLVE_BIN
// A scene whose surface aborts TetGen: `tissue_solve` exits 1 with one line, not by a signal.
TEST(TetgenBadSurface, SolveExitsWithOneLine) {
  test::TempDir dir;
  const std::string scene = test::write_file(
      dir.file("scene.yaml"), "mesh: {file: " + kBad +
                                  "flat_cube.obj}\n"
                                  "material: {young_modulus: 3000.0, poisson_ratio: 0.45}\n");
  const std::string err = dir.file("err.txt");
  const std::string cmd = std::string(TISSUE_SOLVE_BIN) + " " + scene + " --out " +
                          dir.file("o.vtk") + " 2>" + err + " >/dev/null";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << "tissue_solve killed by a signal";
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::string text = test::read_text(err);
  while (!text.empty() && text.back() == '\n') text.pop_back();
  EXPECT_EQ(text.find('\n'), std::string::npos) << text;
  EXPECT_NE(text.find(kBad + "flat_cube.obj: TetGen crashed (signal 6, SIGABRT)"),
            std::string::npos)
      << text;
}
#endif

}  // namespace
}  // namespace stc
