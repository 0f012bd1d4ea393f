// `puzzlecal calibrate` with videos, run as a user runs it: a folder
// mixing the sample photos, a rendered clip of the same lens and a file
// that only claims to be a video. The clip's frames join the photos, a line
// says what became of its frames, the report folder holds its frame table,
// and the false video is named with the reason while the run goes on.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "formats/camera_yaml.h"
#include "sim/video_clip.h"
#include "tests/support/files.h"
#include "tests/support/program_run.h"

namespace puzzlecal {
namespace {

namespace fs = std::filesystem;

fs::path VideoInputScratch() {
  return fs::temp_directory_path() /
         ("puzzlecal_video_input_test_" + std::to_string(::getpid()));
}

const auto* const kVideoInputCleanup = ::testing::AddGlobalTestEnvironment(
    new testing_program::RemoveAtEnd(VideoInputScratch()));

TEST(VideoInput, AFolderMixingPhotosAndVideosCalibrates) {
  const fs::path folder = VideoInputScratch() / "mixed";
  fs::create_directories(folder);
  for (const auto& entry : fs::directory_iterator("testdata/sample")) {
    if (entry.path().extension() == ".png") {
      fs::copy_file(entry.path(), folder / entry.path().filename());
    }
  }
  // The sample photos' lens and size (sim/scenes.h SampleScene).
  const ClipSpec clip = SampleClip(4, 10, 800, 600);
  std::string error;
  ASSERT_TRUE(RenderClip(clip, (folder / "clip.avi").string(), 2, nullptr,
                         &error))
      << error;
  testing_files::WriteFile(folder / "broken.mp4", "not a video\n");
  const fs::path camera_file = VideoInputScratch() / "camera.yaml";
  const fs::path report = VideoInputScratch() / "report";
  const testing_program::ProgramRun run = testing_program::RunProgram(
      "calibrate --images " + testing_program::Quote(folder.string()) +
          " --board configs/boards/puzzleboard_23x16_30mm.yaml --out " +
          testing_program::Quote(camera_file.string()) + " --report " +
          testing_program::Quote(report.string()),
      VideoInputScratch());
  ASSERT_EQ(run.exit_code, 0) << run.all();
  EXPECT_NE(run.out.find("clip.avi: 40 frames"), std::string::npos)
      << run.out;
  EXPECT_NE(run.err.find("broken.mp4: unreadable (not a readable video"),
            std::string::npos)
      << run.err;
  // The photos and the clip's frames: f within 0.05 % of the truth.
  Camera camera;
  ASSERT_TRUE(ReadCameraFile(camera_file.string(), &camera, &error)) << error;
  for (int p = 0; p < 2; ++p) {
    const double truth = clip.camera.params[p];
    EXPECT_LT(std::abs(camera.params[p] - truth) / truth, 0.0005);
  }
  const std::string table =
      testing_files::ReadFile(report / "video_frames_clip.avi.csv");
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 41) << table;
  EXPECT_NE(table.find(",kept,"), std::string::npos);
  const std::string summary = testing_files::ReadFile(report / "summary.md");
  EXPECT_NE(summary.find("clip.avi#frame00"), std::string::npos);
}

TEST(VideoInput, AFalseVideoAloneIsBadInputNamingIt) {
  const fs::path fake = VideoInputScratch() / "alone.avi";
  fs::create_directories(VideoInputScratch());
  testing_files::WriteFile(fake, "RIFF but nothing more");
  const testing_program::ProgramRun run = testing_program::RunProgram(
      "calibrate --images " + testing_program::Quote(fake.string()) +
          " --board configs/boards/puzzleboard_23x16_30mm.yaml --out " +
          testing_program::Quote((VideoInputScratch() / "c.yaml").string()),
      VideoInputScratch());
  EXPECT_EQ(run.exit_code, 3) << run.all();
  EXPECT_NE(run.err.find("alone.avi: not a readable video"), std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace puzzlecal
