// Trajectory files (head pose + gaze per frame): what is read, and every malformed line refused
// with its file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pvr/app/trajectory.h"
#include "pvr/util/error.h"

namespace pvr {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  std::filesystem::path p = std::filesystem::temp_directory_path() / ("pvr_traj_" + name);
  std::ofstream(p) << text;
  return p.string();
}

TEST(Trajectory, ReadsPosesAndGazeOfBothForms) {
  std::string path = writeTemp("good.txt",
                               "# a comment\n"
                               "\n"
                               "0 0.5 1   0 0 0 2   0.25 0.75   # quaternion normalized on reading\n"
                               "1 2 3   0 0.7071068 0 0.7071068   0.1 0.2   0.3 0.4\n");
  std::vector<TrajectoryFrame> frames = loadTrajectory(path);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_FLOAT_EQ(frames[0].head.position.y, 0.5f);
  EXPECT_FLOAT_EQ(frames[0].head.orientation.w, 1.0f);
  EXPECT_FLOAT_EQ(frames[0].gaze[0][0], 0.25f);
  EXPECT_FLOAT_EQ(frames[0].gaze[1][1], 0.75f);  // one gaze for both eyes
  EXPECT_FLOAT_EQ(frames[1].gaze[0][1], 0.2f);
  EXPECT_FLOAT_EQ(frames[1].gaze[1][0], 0.3f);
  EXPECT_TRUE(frames[0].verge);
  EXPECT_FALSE(frames[1].verge);
  Vec3 forward = frames[1].head.orientation.rotate({0, 0, -1});
  EXPECT_NEAR(forward.x, -1.0f, 1e-5f);  // 90 degrees about +Y turns -Z to -X
  std::filesystem::remove(path);
}

TEST(Trajectory, RefusesMalformedFiles) {
  const std::pair<const char*, const char*> bad[] = {
      {"count", "0 0 0 0 0 0 1 0.5\n"},
      {"word", "0 0 0 0 0 0 1 0.5 half\n"},
      {"nan", "0 nan 0 0 0 0 1 0.5 0.5\n"},
      {"zero_quaternion", "0 0 0 0 0 0 0 0.5 0.5\n"},
      {"gaze", "0 0 0 0 0 0 1 1.5 0.5\n"},
      {"empty", "# nothing\n\n"},
  };
  for (auto [name, text] : bad) {
    std::string path = writeTemp(name, text);
    EXPECT_THROW(loadTrajectory(path), Error) << name;
    std::filesystem::remove(path);
  }
  EXPECT_THROW(loadTrajectory("/nonexistent/trajectory.txt"), Error);
  std::string path = writeTemp("line", "0 0 0 0 0 0 1 0.5 0.5\n0 0 0 0 0 0 1 0.5\n");
  try {
    loadTrajectory(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace pvr
