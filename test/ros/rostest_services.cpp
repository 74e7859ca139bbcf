// (b) Services: ~reset restores the initial surface bit for bit (also after a ~cut, and equal
// to a fresh core Simulation), ~cut through the operation region splits tets and the surface
// gains cut faces, ~set_cutting, ~save writes a readable VTK (errors come back, no crash).
#include "soft_tissue_cutting/generators/thigh.hpp"
#include "soft_tissue_cutting/simulation/simulation.hpp"
#include "soft_tissue_cutting/solve/blas_kernels.hpp"
#include "test_helpers.hpp"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/Cut.h>
#include <soft_tissue_cutting/SaveMesh.h>
#include <soft_tissue_cutting/SimStats.h>
#include <std_srvs/SetBool.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <string>

using tissue_test::spin_until;

namespace {

struct Fixture : testing::Test {
  ros::NodeHandle nh;
  std::deque<visualization_msgs::Marker> surfaces;
  std::deque<visualization_msgs::MarkerArray> markers;
  ros::Subscriber surface_sub, markers_sub;

  void SetUp() override {
    ASSERT_TRUE(ros::service::waitForService("/tissue/reset", ros::Duration(20)));
    surface_sub = nh.subscribe<visualization_msgs::Marker>(
        "/tissue/surface", 200, [this](const visualization_msgs::Marker::ConstPtr& m) {
          surfaces.push_back(*m);
          if (surfaces.size() > 200) surfaces.pop_front();
        });
    markers_sub = nh.subscribe<visualization_msgs::MarkerArray>(
        "/tissue/markers", 200, [this](const visualization_msgs::MarkerArray::ConstPtr& m) {
          markers.push_back(*m);
          if (markers.size() > 200) markers.pop_front();
        });
    ASSERT_TRUE(spin_until([this] { return !surfaces.empty(); }, 10.0));
  }

  // Calls ~reset and returns the first surface the node published after it with as many
  // points as the initial surface (every surface before the reset in these tests is either the
  // initial one or a cut one, which has more points). No state travels in strings.
  bool reset_and_capture(visualization_msgs::Marker* out) {
    static const size_t initial_points = [] {
      stc::Simulation fresh(stc::make_thigh_scene());
      return 3 * fresh.surface().triangles.size();
    }();
    tissue_test::spin_for(0.1);
    surfaces.clear();
    std_srvs::Trigger t;
    if (!ros::service::call("/tissue/reset", t) || !t.response.success) return false;
    return spin_until(
        [&] {
          for (const auto& s : surfaces)
            if (s.points.size() == initial_points) {
              *out = s;
              return true;
            }
          return false;
        },
        5.0);
  }
};

// A stroke through the thigh's operation region: tip 12 mm deep, edge radially outward
// (local +x = +x), drawn along z across the region (as the scene's scripted scalpel does).
std::vector<geometry_msgs::PoseStamped> stroke(const std::string& frame = "") {
  std::vector<geometry_msgs::PoseStamped> poses;
  for (double z = 0.028; z <= 0.0681; z += 0.005) {
    geometry_msgs::PoseStamped p;
    p.header.frame_id = frame;
    p.pose.position.x = 0.048;
    p.pose.position.y = 0.003;
    p.pose.position.z = z;
    p.pose.orientation.w = 1;
    poses.push_back(p);
  }
  return poses;
}

}  // namespace

TEST_F(Fixture, ResetRestoresInitialSurfaceBitForBit) {
  visualization_msgs::Marker first, second;
  ASSERT_TRUE(reset_and_capture(&first));

  // Identical to a fresh start: the core's own fresh Simulation draws the same points.
  {
    stc::Simulation fresh(stc::make_thigh_scene());
    const stc::DeformedSurface s = fresh.surface();
    ASSERT_EQ(first.points.size(), 3 * s.triangles.size());
    bool same = true;
    size_t i = 0;
    for (const auto& t : s.triangles)
      for (int v : t.nodes) {
        const auto& p = first.points[i++];
        same = same && p.x == s.positions[v].x() && p.y == s.positions[v].y() &&
               p.z == s.positions[v].z();
      }
    EXPECT_TRUE(same) << "the surface after ~reset differs from a fresh Simulation's";
  }

  soft_tissue_cutting::Cut cut;
  cut.request.poses = stroke();
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  tissue_test::spin_for(0.5);  // let the loop step on the cut mesh

  ASSERT_TRUE(reset_and_capture(&second));
  EXPECT_TRUE(tissue_test::same_points(first, second))
      << "~reset after a ~cut must restore the initial surface bit for bit";
  EXPECT_EQ(first.colors.size(), second.colors.size());
}

TEST_F(Fixture, CutThroughOperationRegionSplitsTetsAndShowsCutFaces) {
  visualization_msgs::Marker initial;
  ASSERT_TRUE(reset_and_capture(&initial));
  markers.clear();
  soft_tissue_cutting::Cut cut;
  cut.request.poses = stroke();
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_TRUE(cut.response.success) << cut.response.message;
  EXPECT_GT(cut.response.tets_split, 0u) << cut.response.message;
  EXPECT_GT(cut.response.cut_faces, 0u) << cut.response.message;
  const bool shown = spin_until(
      [&] {
        for (const auto& a : markers)
          for (const auto& m : a.markers)
            if (m.ns == "cut_faces" && m.action == visualization_msgs::Marker::ADD &&
                !m.points.empty())
              return true;
        return false;
      },
      5.0);
  EXPECT_TRUE(shown) << "no cut_faces triangles on ~markers after the cut";
  visualization_msgs::Marker after;
  ASSERT_TRUE(reset_and_capture(&after));
}

TEST_F(Fixture, CutInUnknownFrameIsRefused) {
  soft_tissue_cutting::Cut cut;
  cut.request.poses = stroke("no_such_frame");
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_FALSE(cut.response.success);
  EXPECT_NE(cut.response.message.find("no_such_frame"), std::string::npos) << cut.response.message;
}

TEST_F(Fixture, SetCutting) {
  std_srvs::SetBool b;
  b.request.data = false;
  ASSERT_TRUE(ros::service::call("/tissue/set_cutting", b));
  EXPECT_TRUE(b.response.success);
  bool param = true;
  EXPECT_TRUE(ros::param::get("/tissue/cutting_enabled", param));
  EXPECT_FALSE(param) << "dynamic_reconfigure's cutting_enabled follows ~set_cutting";
  b.request.data = true;
  ASSERT_TRUE(ros::service::call("/tissue/set_cutting", b));
  EXPECT_TRUE(b.response.success);
  EXPECT_TRUE(ros::param::get("/tissue/cutting_enabled", param));
  EXPECT_TRUE(param);
}

// dynamic_reconfigure's values are what the simulation uses, and stay so through ~reset (they
// used to fall back to the scene's while the server kept showing the tuned ones): /diagnostics
// reports the values in use.
TEST_F(Fixture, TuningSurvivesReset) {
  std::map<std::string, std::string> diagnostics;
  int seen = 0;
  ros::Subscriber diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArray::ConstPtr& a) {
        for (const auto& s : a->status)
          if (s.name.find("simulation") != std::string::npos) {
            for (const auto& kv : s.values) diagnostics[kv.key] = kv.value;
            ++seen;
          }
      });
  auto reconfigure = [](double pressure, double guard) {
    dynamic_reconfigure::Reconfigure r;
    dynamic_reconfigure::DoubleParameter p;
    p.name = "cut_pressure";
    p.value = pressure;
    r.request.config.doubles.push_back(p);
    p.name = "shape_guard_deg";
    p.value = guard;
    r.request.config.doubles.push_back(p);
    return ros::service::call("/tissue/set_parameters", r);
  };
  // Two reports after `since`: the second was made wholly after the change.
  auto reported = [&](const std::string& key, double value) {
    const int since = seen;
    return spin_until(
        [&] {
          const auto it = diagnostics.find(key);
          return seen >= since + 2 && it != diagnostics.end() &&
                 std::abs(std::stod(it->second) - value) < 1e-9;
        },
        5.0);
  };
  double pressure = 0, guard = 0;
  ASSERT_TRUE(ros::param::get("/tissue/cut_pressure", pressure));
  ASSERT_TRUE(ros::param::get("/tissue/shape_guard_deg", guard));
  EXPECT_EQ(guard, 5.0) << "the scene's default shape guard";
  ASSERT_TRUE(reported("shape guard (deg)", guard)) << "no /diagnostics with the shape guard";
  ASSERT_TRUE(reconfigure(0.25, 1.0));
  EXPECT_TRUE(reported("shape guard (deg)", 1.0));
  EXPECT_TRUE(reported("cut pressure (N)", 0.25));
  visualization_msgs::Marker reset_surface;
  ASSERT_TRUE(reset_and_capture(&reset_surface));
  EXPECT_TRUE(reported("shape guard (deg)", 1.0)) << "the reset dropped the tuned shape guard";
  EXPECT_TRUE(reported("cut pressure (N)", 0.25)) << "the reset dropped the tuned cut pressure";
  ASSERT_TRUE(reconfigure(pressure, guard));  // as the other tests expect it
  EXPECT_TRUE(reported("shape guard (deg)", guard));
}

TEST_F(Fixture, SaveWritesReadableVtk) {
  soft_tissue_cutting::SimStats::ConstPtr stats =
      ros::topic::waitForMessage<soft_tissue_cutting::SimStats>("/tissue/stats", nh,
                                                                ros::Duration(5));
  ASSERT_TRUE(stats);
  const std::string base = "/tmp/rostest_services_" + std::to_string(getpid());
  soft_tissue_cutting::SaveMesh save;
  save.request.path = base + ".vtk";
  save.request.stats_path = base + ".json";
  ASSERT_TRUE(ros::service::call("/tissue/save", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  std::ifstream vtk(save.request.path);
  std::string line, all;
  ASSERT_TRUE(std::getline(vtk, line));
  EXPECT_EQ(line.rfind("# vtk DataFile Version", 0), 0u) << line;
  while (std::getline(vtk, line)) all += line + "\n";
  EXPECT_NE(all.find("UNSTRUCTURED_GRID"), std::string::npos);
  // No scalpel in this test, so the node count does not change between ~stats and ~save.
  EXPECT_NE(all.find("POINTS " + std::to_string(stats->nodes) + " "), std::string::npos);
  EXPECT_NE(all.find("displacement"), std::string::npos);
  std::ifstream json(save.request.stats_path);
  std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"tets\""), std::string::npos) << text;
}

TEST_F(Fixture, RepeatedCutGivesTheTrueReason) {
  visualization_msgs::Marker initial;
  ASSERT_TRUE(reset_and_capture(&initial));
  soft_tissue_cutting::Cut cut;
  cut.request.poses = stroke();
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  ASSERT_TRUE(cut.response.success) << cut.response.message;
  // Again: a few passes may still open faces where the first one snapped (each carries the
  // path to rest coordinates through the tissue the last one opened; 4 passes since stop 47,
  // 5 since the 5 deg guard moves refused crossings along their edges (stop 51), as
  // CutPathSampling.RepeatedCutSaysItIsAlreadyCut); then the reply names the true reason (not
  // "does not cross the operation part").
  int passes = 0;
  do {
    ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
    ++passes;
  } while (cut.response.success && passes < 6);
  EXPECT_LE(passes, 5);
  EXPECT_FALSE(cut.response.success);
  EXPECT_NE(cut.response.message.find("already cut"), std::string::npos) << cut.response.message;
}

TEST_F(Fixture, ZeroQuaternionAndLongFramesAreReportedBriefly) {
  soft_tissue_cutting::Cut cut;
  cut.request.poses = stroke();
  cut.request.poses[3].pose.orientation.w = 0;
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_FALSE(cut.response.success);
  EXPECT_EQ(cut.response.message, "pose 3: zero quaternion");
  cut.request.poses = stroke(std::string(1 << 20, 'f'));  // a 1 MB frame name
  ASSERT_TRUE(ros::service::call("/tissue/cut", cut));
  EXPECT_FALSE(cut.response.success);
  EXPECT_LT(cut.response.message.size(), 600u);
  EXPECT_NE(cut.response.message.find("(1048576 bytes)"), std::string::npos);
}

TEST_F(Fixture, SaveSucceedsOnlyWhenEverythingWasWritten) {
  const std::string base = "/tmp/rostest_services_partial_" + std::to_string(getpid());
  std::remove((base + ".vtk").c_str());
  soft_tissue_cutting::SaveMesh save;
  save.request.path = base + ".vtk";
  save.request.stats_path = "/nonexistent_dir_for_tissue_test/x.json";
  ASSERT_TRUE(ros::service::call("/tissue/save", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_NE(save.response.message.find("x.json"), std::string::npos) << save.response.message;
  EXPECT_FALSE(std::ifstream(save.request.path).good()) << "a failed ~save left a partial VTK";
  EXPECT_FALSE(std::ifstream(save.request.path + ".part").good());
  save.request.path = "/tmp/" + std::string(1 << 20, 'p') + ".vtk";
  save.request.stats_path = "";
  ASSERT_TRUE(ros::service::call("/tissue/save", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_LT(save.response.message.size(), 600u);
}

TEST_F(Fixture, SaveToBadPathReportsErrorAndNodeLivesOn) {
  soft_tissue_cutting::SaveMesh save;
  save.request.path = "/nonexistent_dir_for_tissue_test/x.vtk";
  ASSERT_TRUE(ros::service::call("/tissue/save", save));
  EXPECT_FALSE(save.response.success);
  EXPECT_FALSE(save.response.message.empty());
  save.request.path = "";
  ASSERT_TRUE(ros::service::call("/tissue/save", save));
  EXPECT_FALSE(save.response.success);
  soft_tissue_cutting::SimStats::ConstPtr s =
      ros::topic::waitForMessage<soft_tissue_cutting::SimStats>("/tissue/stats", nh,
                                                                ros::Duration(5));
  EXPECT_TRUE(s) << "node stopped publishing ~stats";
}

int main(int argc, char** argv) {
  // The node's BLAS kernels (solve/blas_kernels.hpp): what this process computes with the
  // core is compared with the node's output bit for bit.
  stc::reexec_with_native_blas_kernels(argv);
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_services");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
