#include "pdvo/common/dataset.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <vector>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {
namespace fs = std::filesystem;

cv::Mat Pattern(int value) {
  cv::Mat m(24, 32, CV_8UC3, cv::Scalar(value, 255 - value, 7));
  return m;
}

// An MJPG video at 10 Hz of `frames` patterns, the i-th Pattern(step * i); false if OpenCV cannot write one.
bool WritePatternVideo(const std::string& path, int frames, int step) {
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, cv::Size(32, 24));
  if (!writer.isOpened()) return false;
  for (int i = 0; i < frames; ++i) writer << Pattern(step * i);
  return true;
}

TEST(FileIo, TruncatedPngIsAnIoErrorNamingTheFile) {
  test::TempDir dir;
  cv::Mat noise(64, 64, CV_8UC3);
  cv::randu(noise, 0, 255);
  WriteImage(dir / "full.png", noise);
  const std::string bytes = ReadFile(dir / "full.png");
  WriteFileAtomically(dir / "cut.png", bytes.substr(0, bytes.size() / 2));
  EXPECT_EQ(ReadImage(dir / "full.png", cv::IMREAD_COLOR).cols, 64);
  try {
    ReadImage(dir / "cut.png", cv::IMREAD_COLOR);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.png: cannot decode image"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadImage(dir / "none.png", cv::IMREAD_COLOR), IoError);
  // One flipped bit in the pixel data: refused before libpng sees it (which would print a line of its own).
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 4;
  WriteFileAtomically(dir / "flipped.png", flipped);
  try {
    ReadImage(dir / "flipped.png", cv::IMREAD_COLOR);
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(
        std::string(e.what()).find("flipped.png: cannot decode image (corrupt PNG: its IDAT chunk fails its CRC)"),
        std::string::npos)
        << e.what();
  }
}

TEST(FileIo, AtomicWriteLeavesNoTemporaryFile) {
  test::TempDir dir;
  WriteFileAtomically(dir / "sub/a.txt", "hello");
  EXPECT_EQ(ReadFile(dir / "sub/a.txt"), "hello");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir / "sub")) files += e.is_regular_file();
  EXPECT_EQ(files, 1);
}

// The names in a folder, hidden ones too, sorted.
std::vector<std::string> Names(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(FileIo, AtomicWriteThroughALinkKeepsTheLink) {
  test::TempDir dir;
  WriteFileAtomically(dir / "real.txt", "old");
  fs::create_symlink("real.txt", dir / "link.txt");
  WriteFileAtomically(dir / "link.txt", "new");
  EXPECT_TRUE(fs::is_symlink(dir / "link.txt"));
  EXPECT_EQ(ReadFile(dir / "real.txt"), "new");
  EXPECT_EQ(Names(dir.str()), (std::vector<std::string>{"link.txt", "real.txt"}));
}

TEST(StagedOutputDir, NothingAppearsBeforeCommitAndNothingIsLeftAfter) {
  test::TempDir dir;
  {
    StagedOutputDir out(dir / "run");
    WriteFileAtomically(out.path("a.txt"), "1");
    EXPECT_FALSE(fs::exists(dir / "run"));
    EXPECT_EQ(out.final_path("a.txt"), (fs::absolute(dir / "run") / "a.txt").string());
    out.Commit();
  }
  EXPECT_EQ(Names(dir.str()), std::vector<std::string>{"run"});  // no staging folder beside it
  EXPECT_EQ(Names(dir / "run"), (std::vector<std::string>{kOutputMarker, "a.txt"}));
  { StagedOutputDir failed(dir / "new"); }  // a run that never commits leaves nothing, not even the folder
  EXPECT_EQ(Names(dir.str()), std::vector<std::string>{"run"});
}

TEST(StagedOutputDir, ASecondRunReplacesTheFirstWholeAndAFailedOneChangesNothing) {
  test::TempDir dir;
  {
    StagedOutputDir first(dir / "run");
    WriteFileAtomically(first.path("a.txt"), "first");
    WriteFileAtomically(first.path("sub/b.txt"), "first");
    first.Commit();
  }
  {
    StagedOutputDir failed(dir / "run");
    WriteFileAtomically(failed.path("a.txt"), "failed");
  }  // no Commit: as if the run threw
  EXPECT_EQ(ReadFile(dir / "run/a.txt"), "first");
  EXPECT_EQ(ReadFile(dir / "run/sub/b.txt"), "first");
  {
    StagedOutputDir second(dir / "run/");  // a trailing slash names the same folder
    WriteFileAtomically(second.path("c.txt"), "second");
    second.Commit();
  }
  EXPECT_EQ(Names(dir / "run"), (std::vector<std::string>{kOutputMarker, "c.txt"}));  // nothing of the first
  EXPECT_EQ(Names(dir.str()), std::vector<std::string>{"run"});
}

TEST(StagedOutputDir, AFolderPdvoDidNotWriteIsRefusedUntouched) {
  test::TempDir dir;
  WriteFileAtomically(dir / "mine/notes.txt", "the user's");
  try {
    StagedOutputDir out(dir / "mine");
    FAIL() << "a foreign folder was accepted";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("mine: is not empty and holds no earlier pdvo output"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(ReadFile(dir / "mine/notes.txt"), "the user's");
  EXPECT_EQ(Names(dir.str()), std::vector<std::string>{"mine"});
  WriteFileAtomically(dir / "file", "x");
  EXPECT_THROW(StagedOutputDir(dir / "file"), IoError);
  fs::create_directories(dir / "empty");  // an empty folder the user made is fine
  StagedOutputDir out(dir / "empty");
  out.Commit();
  EXPECT_TRUE(fs::exists(fs::path(dir / "empty") / kOutputMarker));
}

TEST(StagedOutputDir, ALinkToAFolderIsFollowedAndKept) {
  test::TempDir dir;
  fs::create_directories(dir / "disk");
  fs::create_directory_symlink("disk", dir / "run");
  for (const char* name : {"first.txt", "second.txt"}) {
    StagedOutputDir out(dir / "run");
    WriteFileAtomically(out.path(name), name);
    out.Commit();
  }
  EXPECT_TRUE(fs::is_symlink(dir / "run"));
  EXPECT_EQ(Names(dir / "disk"), (std::vector<std::string>{kOutputMarker, "second.txt"}));
  EXPECT_EQ(Names(dir.str()), (std::vector<std::string>{"disk", "run"}));
}

TEST(StagedOutputDir, StagingLeftByADeadProcessIsRemovedALiveOnesIsNot) {
  test::TempDir dir;
  const std::string dead = dir / ".run.partial-999999999";  // above any pid_max: no such process
  const std::string live = dir / ".run.partial-1";          // init always runs
  const std::string other = dir / ".other.partial-999999999";
  for (const std::string& folder : {dead, live, other}) WriteFileAtomically(folder + "/x", "x");
  StagedOutputDir out(dir / "run");
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));  // another folder's staging is that folder's business
}

// A process killed inside Commit, where the file system cannot exchange two paths, may leave the earlier output
// moved aside (staging + ".old"): it goes back if the new output had not taken its place yet, and is removed if it had.
TEST(StagedOutputDir, AnEarlierOutputMovedAsideByADeadProcessIsPutBack) {
  test::TempDir dir;
  const std::string aside = dir / ".run.partial-999999999.old";  // above any pid_max: no such process
  WriteFileAtomically(aside + "/" + kOutputMarker, "pdvo output\n");
  WriteFileAtomically(aside + "/result.txt", "the user's earlier run");
  {
    StagedOutputDir out(dir / "run");
    EXPECT_FALSE(fs::exists(aside));
    EXPECT_EQ(ReadFile(dir / "run/result.txt"), "the user's earlier run");
  }
  WriteFileAtomically(aside + "/result.txt", "older still");  // the new output was already in place
  StagedOutputDir again(dir / "run");
  EXPECT_FALSE(fs::exists(aside));
  EXPECT_EQ(ReadFile(dir / "run/result.txt"), "the user's earlier run");
}

TEST(Dataset, ImageFolderSortedWithTimes) {
  test::TempDir dir;
  for (int i : {2, 0, 1}) WriteImage(dir / ("img_" + std::to_string(i) + ".png"), Pattern(i * 50));
  WriteFileAtomically(dir / "times.txt", "0.5\n0.75\n1.0\n");
  SequenceOptions options;
  options.times_path = dir / "times.txt";
  auto seq = OpenSequence(dir.str(), options);
  EXPECT_EQ(seq->size(), 3u);
  Frame f;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(seq->Next(&f));
    EXPECT_EQ(f.index, static_cast<size_t>(i));
    EXPECT_EQ(f.image.at<cv::Vec3b>(0, 0)[0], i * 50);
    EXPECT_DOUBLE_EQ(f.timestamp, 0.5 + 0.25 * i);
    EXPECT_TRUE(f.depth.empty());
  }
  EXPECT_FALSE(seq->Next(&f));
}

TEST(Dataset, ImageFolderErrors) {
  test::TempDir dir;
  EXPECT_THROW(OpenSequence(dir.str()), FormatError);  // empty
  EXPECT_THROW(OpenSequence(dir / "missing"), IoError);
  WriteImage(dir / "a.png", Pattern(1));
  WriteFileAtomically(dir / "b.png", "not a png");
  auto seq = OpenSequence(dir.str());
  Frame f;
  EXPECT_TRUE(seq->Next(&f));
  EXPECT_THROW(seq->Next(&f), IoError);
}

TEST(Dataset, TumFolderAssociatesDepthAndGroundTruth) {
  test::TempDir dir;
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "depth");
  std::string rgb = "# color images\n", depth = "# depth\n";
  for (int i = 0; i < 3; ++i) {
    const double t = 10.0 + i / 30.0;
    WriteImage(dir / ("rgb/" + std::to_string(i) + ".png"), Pattern(i));
    cv::Mat d(24, 32, CV_16U, cv::Scalar(5000 * (i + 1)));
    WriteImage(dir / ("depth/" + std::to_string(i) + ".png"), d);
    rgb += std::to_string(t) + " rgb/" + std::to_string(i) + ".png\n";
    depth += std::to_string(t + 0.005) + " depth/" + std::to_string(i) + ".png\n";
  }
  WriteFileAtomically(dir / "rgb.txt", rgb);
  WriteFileAtomically(dir / "depth.txt", depth);
  // Ground truth only near the first two frames.
  WriteFileAtomically(dir / "groundtruth.txt", "10.001 1 2 3 0 0 0 1\n10.034 4 5 6 0 0 0 1\n");
  auto seq = OpenSequence(dir.str());
  Frame f;
  ASSERT_TRUE(seq->Next(&f));
  EXPECT_FLOAT_EQ(f.depth.at<float>(3, 3), 1.0f);
  ASSERT_TRUE(f.world_from_cam.has_value());
  EXPECT_DOUBLE_EQ(f.world_from_cam->translation.x(), 1.0);
  ASSERT_TRUE(seq->Next(&f));
  EXPECT_FLOAT_EQ(f.depth.at<float>(0, 0), 2.0f);
  EXPECT_DOUBLE_EQ(f.world_from_cam->translation.x(), 4.0);
  ASSERT_TRUE(seq->Next(&f));
  EXPECT_FALSE(f.world_from_cam.has_value());  // 32 ms from the nearest pose
  EXPECT_FALSE(seq->Next(&f));
}

TEST(Dataset, TumListErrors) {
  test::TempDir dir;
  WriteFileAtomically(dir / "rgb.txt", "1.0 rgb/a.png\n0.5 rgb/b.png\n");
  EXPECT_THROW(OpenSequence(dir.str()), FormatError);
  WriteFileAtomically(dir / "rgb.txt", "# nothing\n");
  EXPECT_THROW(OpenSequence(dir.str()), FormatError);
}

TEST(Dataset, KittiFolderReadsCalibTimesAndPoses) {
  test::TempDir dir;
  fs::create_directories(dir / "image_0");
  for (int i = 0; i < 2; ++i) {
    cv::imwrite(dir / ("image_0/00000" + std::to_string(i) + ".png"), cv::Mat(20, 30, CV_8U, cv::Scalar(9)));
  }
  WriteFileAtomically(dir / "calib.txt", "P0: 700 0 15 0 0 701 10 0 0 0 1 0\nP1: 700 0 15 -380 0 701 10 0 0 0 1 0\n");
  WriteFileAtomically(dir / "times.txt", "0.0\n0.1\n");
  WriteFileAtomically(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1.5\n");
  auto seq = OpenSequence(dir.str());
  ASSERT_TRUE(seq->camera().has_value());
  EXPECT_EQ(seq->camera()->width, 30);
  EXPECT_DOUBLE_EQ(seq->camera()->fy, 701);
  Frame f;
  ASSERT_TRUE(seq->Next(&f));
  ASSERT_TRUE(seq->Next(&f));
  EXPECT_EQ(f.image.channels(), 3);
  EXPECT_DOUBLE_EQ(f.timestamp, 0.1);
  EXPECT_DOUBLE_EQ(f.world_from_cam->translation.z(), 1.5);
  WriteFileAtomically(dir / "calib.txt", "P0: 700 0 15\n");
  EXPECT_THROW(OpenSequence(dir.str()), FormatError);
}

TEST(Dataset, VideoFile) {
  test::TempDir dir;
  const std::string path = dir / "v.avi";
  ASSERT_TRUE(WritePatternVideo(path, 5, 40));
  auto seq = OpenSequence(path);
  Frame f;
  int n = 0;
  while (seq->Next(&f)) {
    EXPECT_NEAR(f.image.at<cv::Vec3b>(12, 16)[0], 40 * n, 12);  // lossy codec
    EXPECT_NEAR(f.timestamp, n / 10.0, 1e-9);
    ++n;
  }
  EXPECT_EQ(n, 5);
  WriteFileAtomically(dir / "bad.avi", "garbage");
  EXPECT_THROW(OpenSequence(dir / "bad.avi"), IoError);
}

// A video cut short is an error naming it, not a shorter video; without its index at the end, all is read.
TEST(Dataset, TruncatedVideoIsAnError) {
  test::TempDir dir;
  const std::string path = dir / "v.avi";
  ASSERT_TRUE(WritePatternVideo(path, 40, 6));
  const std::string whole = ReadFile(path);
  const auto frames_read = [&](const std::string& bytes) {
    WriteFileAtomically(dir / "cut.avi", bytes);
    auto seq = OpenSequence(dir / "cut.avi");
    Frame f;
    int n = 0;
    while (seq->Next(&f)) ++n;
    return n;
  };
  EXPECT_EQ(frames_read(whole), 40);
  try {
    frames_read(whole.substr(0, whole.size() / 2));
    ADD_FAILURE() << "half a video was read without an error";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.avi: the video ends after "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("of the 40 frames its container lists"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pdvo
