// (c, params) Bad private parameters are refused at start with one FATAL line naming the
// parameter and exit status 2 (a bad scene: 1), instead of running on a default: ros::param
// keeps the default when the type is wrong (`_rate:=fast` used to step at 100 Hz). An int
// where a number is asked (`_rate:=50`) is a number: that node starts and steps.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <soft_tissue_cutting/SimStats.h>

#include <sys/wait.h>
#include <cstdio>
#include <string>

namespace {

struct NodeRun {
  int status = -1;  // exit status, -1: did not exit by itself within the timeout
  std::string output;
};

// Starts tissue_node with `args` (private parameters as `_name:=value`) under this master and
// waits up to `seconds` for it to exit; stops it (SIGINT) if it is still running then.
NodeRun run_node(const std::string& name, const std::string& args, int seconds) {
  const std::string cmd = "timeout -s INT -k 5 " + std::to_string(seconds) +
                          " rosrun soft_tissue_cutting tissue_node __name:=" + name + " " + args +
                          " 2>&1";
  NodeRun r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, pipe)) r.output += buf;
  const int status = pclose(pipe);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.status = code == 124 ? -1 : code;  // 124: timeout stopped it
  return r;
}

struct Case {
  const char* args;
  const char* message;
};

TEST(BadParams, EachIsRefusedWithItsNameAndTheNodeExits) {
  const Case cases[] = {
      {"_rate:=fast", "~rate must be a number (steps per second)"},
      {"_rate:=0", "~rate must be a positive number of steps per second"},
      {"_every_pose:=maybe", "~every_pose must be true or false"},
      {"_max_cut_poses:=1.5", "~max_cut_poses must be an integer"},
      {"_max_pose_jump:=[1,2]", "~max_pose_jump must be a number (m)"},
      {"_wrench_frame:=world", "~wrench_frame must be tissue or blade, not 'world'"},
      {"_frame_id:=7", "~frame_id must be a string (a tf frame)"},
      {"_backend:=cuda", "~backend must be"},
      {"_parent_transform:=[0,0,0,0,0,0]", "~parent_transform must be a list of 7 numbers"},
      {"_cut_pressure:=hard", "~cut_pressure must be a number (N)"},
      {"_cutting_enabled:=sometimes", "~cutting_enabled must be true or false"},
      {"_shape_guard_deg:=strict", "~shape_guard_deg must be a number (degrees)"},
      {"_shape_guard_deg:=45", "~shape_guard_deg must be in [0, 30] (degrees)"},
  };
  int k = 0;
  for (const Case& c : cases) {
    const NodeRun r = run_node("bad_params_" + std::to_string(k++), c.args, 20);
    std::printf("[bad_params] %s -> exit %d\n", c.args, r.status);
    EXPECT_EQ(r.status, 2) << c.args << ":\n" << r.output;
    EXPECT_NE(r.output.find("tissue_node: bad parameter: " + std::string(c.message)),
              std::string::npos)
        << c.args << ":\n"
        << r.output;
  }
  const NodeRun scene = run_node("bad_scene", "_scene:=/nonexistent/liver.yaml", 20);
  EXPECT_EQ(scene.status, 1) << scene.output;
  EXPECT_NE(scene.output.find("cannot load scene '/nonexistent/liver.yaml'"), std::string::npos)
      << scene.output;
}

TEST(BadParams, AnIntWhereANumberIsAskedIsANumber) {
  ros::NodeHandle nh;
  int stats = 0;
  ros::Subscriber sub = nh.subscribe<soft_tissue_cutting::SimStats>(
      "/int_rate/stats", 100,
      [&stats](const soft_tissue_cutting::SimStats::ConstPtr&) { ++stats; });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  const NodeRun r = run_node("int_rate", "_rate:=50 _max_pose_jump:=1", 6);
  EXPECT_EQ(r.status, -1) << "the node should still run (stopped by the test):\n" << r.output;
  EXPECT_EQ(r.output.find("bad parameter"), std::string::npos) << r.output;
  EXPECT_GT(stats, 20) << "no ~stats from the node started with _rate:=50";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "rostest_bad_params");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
