// The `pdvo` command end to end: exit codes, one-line errors that name the file, no partial output.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"
#include "pdvo/common/trajectory.h"
#include "pdvo/infer/model.h"
#include "pdvo/test/annotations.h"
#include "pdvo/test/scenes.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {
namespace fs = std::filesystem;

struct CommandResult {
  int code;
  std::string out, err;
};

// Runs `pdvo <args>`, capturing stdout and stderr.
CommandResult Pdvo(const std::string& args, const test::TempDir& dir) {
  const std::string out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = std::string(PDVO_BINARY) + " " + args + " > " + out + " 2> " + err;
  const int status = std::system(command.c_str());
  return {WEXITSTATUS(status), ReadFile(out), ReadFile(err)};
}

int Lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// `pdvo <args>` must fail with one line on stderr that contains `text`.
void ExpectError(const std::string& args, const std::string& text, const test::TempDir& dir) {
  const CommandResult r = Pdvo(args, dir);
  EXPECT_NE(r.code, 0) << args;
  EXPECT_EQ(Lines(r.err), 1) << args << ": " << r.err;
  EXPECT_NE(r.err.find(text), std::string::npos) << args << ": " << r.err;
}

// A TUM-style RGB-D folder of the ray-cast room: 3 frames, camera.yaml.
void WriteRoomSequence(const std::string& root) {
  std::vector<test::ScenePlane> planes;
  std::vector<test::SceneSphere> spheres;
  test::RoomScene(&planes, &spheres);
  const Camera camera = test::SceneCamera();
  fs::create_directories(root + "/rgb");
  fs::create_directories(root + "/depth");
  std::string rgb = "# color images\n", depth = "# depth maps\n";
  for (int i = 0; i < 3; ++i) {
    const test::RenderedDepth r = test::RenderDepth(camera, planes, spheres, 0.0012, 0.0019, 20 + i);
    cv::Mat d16, grey;
    r.depth.convertTo(d16, CV_16U, 5000.0);
    r.depth.convertTo(grey, CV_8U, 50.0);
    const std::string name = std::to_string(i);
    cv::imwrite(root + "/rgb/" + name + ".png", grey);
    cv::imwrite(root + "/depth/" + name + ".png", d16);
    rgb += std::to_string(1.0 + i / 30.0) + " rgb/" + name + ".png\n";
    depth += std::to_string(1.0 + i / 30.0) + " depth/" + name + ".png\n";
  }
  WriteFileAtomically(root + "/rgb.txt", rgb);
  WriteFileAtomically(root + "/depth.txt", depth);
  camera.Write(root + "/camera.yaml");
}

TEST(Cli, UsageAndHelp) {
  test::TempDir dir;
  EXPECT_EQ(Pdvo("", dir).code, 1);
  const CommandResult help = Pdvo("--help", dir);
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.out.find("annotate-depth"), std::string::npos);
  EXPECT_EQ(Pdvo("frobnicate", dir).code, 1);
  for (const char* command :
       {"show", "validate", "annotate-depth", "compare", "ate", "detect", "evaluate-detection", "report"}) {
    const CommandResult r = Pdvo(std::string(command) + " --help", dir);
    EXPECT_EQ(r.code, 0) << command;
    EXPECT_NE(r.out.find("--verbosity"), std::string::npos) << command;
  }
  const CommandResult missing = Pdvo("ate --gt x", dir);  // a missing required flag
  EXPECT_EQ(missing.code, 1);
  EXPECT_EQ(Lines(missing.err), 1) << missing.err;
  EXPECT_NE(missing.err.find("pdvo ate: error: --est is required"), std::string::npos) << missing.err;
  // Values CLI11 alone would take: NaN in a range, a negative number for an unsigned flag.
  const std::pair<const char*, const char*> bad[] = {
      {"compare -r a -e b --min-iou nan", "--min-iou: must be a number from 0 to 1, got nan"},
      {"show a.json --alpha 2 --out x.png", "--alpha: must be a number from 0 to 1, got 2"},
      {"synth -o s --seed -1", "--seed: must not be negative, got -1"},
      {"vo -s s -o o --max-frames -1", "--max-frames: must not be negative, got -1"}};
  for (const auto& [args, text] : bad) {
    const CommandResult r = Pdvo(args, dir);
    EXPECT_EQ(r.code, 1) << args;
    EXPECT_EQ(Lines(r.err), 1) << args << ": " << r.err;
    EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
  }
}

TEST(Cli, BadInputsGiveOneLineErrorsNamingTheFile) {
  test::TempDir dir;
  const auto expect_error = [&](const std::string& args, const std::string& text) { ExpectError(args, text, dir); };
  expect_error("show " + (dir / "none.json") + " --out " + (dir / "o.png"), "none.json: file not found");
  WriteFileAtomically(dir / "bad.json", "{ not json");
  expect_error("show " + (dir / "bad.json") + " --out " + (dir / "o.png"), "bad.json: malformed JSON");

  // A valid annotation of a truncated image.
  cv::Mat noise(40, 60, CV_8UC3);
  cv::randu(noise, 0, 255);
  WriteImage(dir / "img.png", noise);
  const std::string png = ReadFile(dir / "img.png");
  WriteFileAtomically(dir / "img.png", png.substr(0, png.size() / 2));
  Annotation a = test::ImageAnnotation(
      "img.png", 60, 40, {test::Shape(kPlaneLabel, {{5, 5}, {30, 5}, {30, 30}}, Eigen::Vector3d(0, 0, -1))});
  WriteAnnotation(dir / "a.json", a);
  expect_error("show " + (dir / "a.json") + " --out " + (dir / "o.png"), "img.png: cannot decode image");
  EXPECT_FALSE(fs::exists(dir / "o.png"));
  // An invalid one: the error names the file and the shape.
  a.shapes[0].points.pop_back();
  WriteAnnotation(dir / "b.json", a);
  expect_error("show " + (dir / "b.json") + " --out " + (dir / "o.png"),
               "b.json: shape 0 (plane): polygon has 2 distinct points");
  const CommandResult v = Pdvo("validate " + (dir / "b.json"), dir);
  EXPECT_EQ(v.code, 2);
  EXPECT_NE(v.out.find("b.json: shape 0 (plane): polygon has 2 distinct points"), std::string::npos);

  WriteFileAtomically(dir / "empty.txt", "# nothing\n");
  WriteFileAtomically(dir / "gt.txt", "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n");
  WriteFileAtomically(dir / "back.txt", "1 0 0 0 0 0 0 1\n0.5 1 0 0 0 0 0 1\n");
  expect_error("ate --gt " + (dir / "gt.txt") + " --est " + (dir / "empty.txt"), "empty.txt: contains no poses");
  expect_error("ate --gt " + (dir / "gt.txt") + " --est " + (dir / "back.txt"),
               "back.txt:2: timestamp 0.5 does not increase");
  expect_error("ate --gt " + (dir / "gt.txt") + " --est " + (dir / "gt.txt") + " --align affine", "unknown alignment");

  WriteRoomSequence(dir / "seq");
  WriteFileAtomically(dir / "cam.yaml", "%YAML:1.0\nwidth: 320\nheight: 240\nfx: 277\ncx: 159.5\ncy: 119.5\n");
  expect_error("annotate-depth -s " + (dir / "seq") + " -o " + (dir / "out") + " -c " + (dir / "cam.yaml"),
               "cam.yaml: missing key 'fy'");
  expect_error("annotate-depth -s " + (dir / "seq") + " -o " + (dir / "out") + " --set inlier_sigma=3",
               "unknown option 'inlier_sigma'");
}

TEST(Cli, AteOfAScaledCopy) {
  test::TempDir dir;
  Trajectory gt;
  for (int i = 0; i < 50; ++i) {
    gt.push_back({i * 0.1, Rigid3d(ExpSO3(Eigen::Vector3d(0, 0.02 * i, 0)),
                                   Eigen::Vector3d(std::sin(0.1 * i), 0.05 * i, i * 0.1))});
  }
  Trajectory est = gt;
  for (StampedPose& p : est) p.world_from_cam.translation *= 0.25;
  WriteTrajectory(dir / "gt.txt", gt, TrajectoryFormat::kTum);
  WriteTrajectory(dir / "est.txt", est, TrajectoryFormat::kTum);
  const CommandResult r = Pdvo(
      "ate --gt " + (dir / "gt.txt") + " --est " + (dir / "est.txt") + " --align sim3 --json " + (dir / "ate.json"),
      dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(ReadFile(dir / "ate.json"));
  EXPECT_NEAR(j["ate"]["scale"].get<double>(), 4.0, 1e-6);
  EXPECT_LT(j["ate"]["translation"]["rmse"].get<double>(), 1e-6);
  EXPECT_EQ(j["ate"]["matched"].get<int>(), 50);

  // Data the alignment cannot use is a data error (exit 2) naming both files, and no report is written.
  Trajectory still = gt, late = gt;
  for (StampedPose& p : still) p.world_from_cam.translation.setZero();
  for (StampedPose& p : late) p.timestamp += 100;
  WriteTrajectory(dir / "still.txt", still, TrajectoryFormat::kTum);
  WriteTrajectory(dir / "late.txt", late, TrajectoryFormat::kTum);
  const std::string gt_flag = " --gt " + (dir / "gt.txt") + " --json " + (dir / "bad.json");
  for (const char* est_name : {"still.txt", "late.txt"}) {
    const CommandResult bad = Pdvo("ate --est " + (dir / est_name) + gt_flag, dir);
    EXPECT_EQ(bad.code, 2) << est_name;
    EXPECT_EQ(Lines(bad.err), 1) << bad.err;
    EXPECT_NE(bad.err.find(std::string(est_name) + " against " + (dir / "gt.txt")), std::string::npos) << bad.err;
  }
  EXPECT_FALSE(fs::exists(dir / "bad.json"));
}

TEST(Cli, AnnotateDepthWritesValidAnnotationsAndNothingOnFailure) {
  test::TempDir dir;
  WriteRoomSequence(dir / "seq");
  const CommandResult ok = Pdvo("annotate-depth -s " + (dir / "seq") + " -o " + (dir / "out"), dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  for (const char* name : {"0.json", "1.json", "2.json", "annotate_depth.yaml"}) {
    EXPECT_TRUE(fs::exists(dir / ("out/" + std::string(name)))) << name;
  }
  const Annotation a = ReadAnnotation(dir / "out/1.json");
  EXPECT_EQ(ResolveImagePath(a, dir / "out/1.json"), fs::path(dir / "seq/rgb/1.png").lexically_normal().string());
  int planes = 0, non_planes = 0;
  for (const AnnotationShape& s : a.shapes) (s.IsPlane() ? planes : non_planes)++;
  EXPECT_GE(planes, 3);
  EXPECT_GE(non_planes, 1);
  EXPECT_EQ(Pdvo("validate " + (dir / "out"), dir).code, 0);
  EXPECT_EQ(Pdvo("show " + (dir / "out/1.json") + " --out " + (dir / "o.png"), dir).code, 0);
  EXPECT_GE(cv::imread(dir / "o.png").rows, 240);  // the legend may pad short images
  // Comparing the output with itself: every plane matched with IoU 1.
  const CommandResult c = Pdvo("compare -r " + (dir / "out") + " -e " + (dir / "out"), dir);
  EXPECT_EQ(c.code, 0);
  EXPECT_NE(c.out.find("IoU median 1.000"), std::string::npos) << c.out;

  // A corrupt depth map in the middle: an error naming it, and no partial output in a new folder.
  WriteFileAtomically(dir / "seq/depth/1.png", "garbage");
  const CommandResult bad = Pdvo("annotate-depth -s " + (dir / "seq") + " -o " + (dir / "out2"), dir);
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("1.png: cannot decode image"), std::string::npos) << bad.err;
  EXPECT_TRUE(!fs::exists(dir / "out2") || fs::is_empty(dir / "out2"));
  // And what the user already had is untouched.
  EXPECT_EQ(Pdvo("annotate-depth -s " + (dir / "seq") + " -o " + (dir / "out"), dir).code, 2);
  EXPECT_TRUE(fs::exists(dir / "out/2.json"));
}

TEST(Cli, SynthWritesASequenceAndRejectsUnknownOptions) {
  test::TempDir dir;
  const CommandResult bad = Pdvo("synth -o " + (dir / "s") + " -n 3 --set street.lopp=true", dir);
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(Lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("unknown option 'lopp'"), std::string::npos) << bad.err;
  const CommandResult ok = Pdvo("synth -o " + (dir / "s") + " -n 3 --seed 5 --set width=160 --set height=120", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(cv::imread(dir / "s/rgb/000002.png").cols, 160);
  EXPECT_EQ(Pdvo("validate " + (dir / "s/annotations"), dir).code, 0);
  EXPECT_TRUE(fs::exists(dir / "s/synth.yaml"));
}

TEST(Cli, VoRunsOnASynthStreetAndRefusesBadInput) {
  test::TempDir dir;
  ASSERT_EQ(Pdvo("synth -o " + (dir / "s") + " -n 20 --seed 4 -v warning", dir).code, 0);
  const CommandResult ok =
      Pdvo("vo -s " + (dir / "s") + " -o " + (dir / "out") + " --mode idpp --overlay -v warning", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(ReadTrajectory(dir / "out/trajectory.txt", TrajectoryFormat::kTum).size(), 20u);
  const nlohmann::json stats = nlohmann::json::parse(ReadFile(dir / "out/stats.json"));
  EXPECT_EQ(stats["totals"]["frames"], 20);
  EXPECT_EQ(stats["frames"].size(), 20u);
  EXPECT_GT(stats["frames"][19]["resident_mib"].get<double>(), 1.0);
  EXPECT_FALSE(fs::exists(dir / "out/stats.json.detections"));  // written as it went, then gathered in
  EXPECT_TRUE(fs::exists(dir / "out/vo.yaml"));
  EXPECT_EQ(ReadFile(dir / "out/map.ply").rfind("ply\n", 0), 0u);
  EXPECT_GT(fs::file_size(dir / "out/overlay.avi"), 1000u);

  // Ground truth and depth maps, which the odometry does not use, are not read: broken ones change nothing.
  const std::string groundtruth = ReadFile(dir / "s/groundtruth.txt");
  WriteFileAtomically(dir / "s/groundtruth.txt", "not a trajectory\n");
  WriteFileAtomically(dir / "s/depth/000003.png", "not a png");
  const CommandResult unread =
      Pdvo("vo -s " + (dir / "s") + " -o " + (dir / "unread") + " --mode idpp -v warning", dir);
  ASSERT_EQ(unread.code, 0) << unread.err;
  EXPECT_EQ(ReadFile(dir / "unread/trajectory.txt"), ReadFile(dir / "out/trajectory.txt"));
  WriteFileAtomically(dir / "s/groundtruth.txt", groundtruth);  // pdvo report reads it

  const auto expect_error = [&](const std::string& args, const std::string& text) { ExpectError(args, text, dir); };
  expect_error("vo -v warning -s " + (dir / "s") + " -c " + (dir / "gone.yaml") + " -o " + (dir / "o1"), "gone.yaml");
  fs::create_directories(dir / "empty");
  expect_error("vo -v warning -s " + (dir / "empty") + " -o " + (dir / "o2"), "empty");
  {
    std::ofstream corrupt(dir / "s/rgb/000007.png", std::ios::trunc);
    corrupt << "not a png";
  }
  expect_error("vo -v warning -s " + (dir / "s") + " -o " + (dir / "o3"), "000007.png");
  for (const char* o : {"o1", "o2", "o3"}) EXPECT_FALSE(fs::exists(dir / o)) << o << ": no partial output";

  // The run's report, and reports of runs that are not there or not whole (the page itself: report_test.cpp).
  const CommandResult report = Pdvo("report " + (dir / "out") + " -o " + (dir / "report.html"), dir);
  ASSERT_EQ(report.code, 0) << report.err;
  EXPECT_NE(ReadFile(dir / "report.html").find("\"frames\":20"), std::string::npos);
  expect_error("report " + (dir / "nothing") + " -o " + (dir / "r1.html"), "nothing/stats.json");
  fs::create_directories(dir / "broken");
  fs::copy_file(dir / "out/trajectory.txt", dir / "broken/trajectory.txt");
  WriteFileAtomically(dir / "broken/stats.json", "{\"totals\": {\"frames\": 20}, \"frames\": []}");
  expect_error("report " + (dir / "broken") + " -o " + (dir / "r2.html"), "broken/stats.json");
  WriteFileAtomically(dir / "broken/stats.json", ReadFile(dir / "out/stats.json"));
  expect_error("report " + (dir / "broken") + " -o " + (dir / "r3.html"), "broken/map.ply");
  expect_error("report " + (dir / "out") + " -o " + (dir / "r4.html") + " --js-dir " + (dir / "nojs"), "three.min.js");
  for (const char* r : {"r1.html", "r2.html", "r3.html", "r4.html"}) EXPECT_FALSE(fs::exists(dir / r)) << r;
}

// pdvo detect on a synthetic street: one valid annotation per image, with scored planes; the same run gives the
// same bytes; bad input is one line naming the file, with no output folder left.
TEST(Cli, DetectWritesAnnotationsAndRefusesBadInput) {
  test::TempDir dir;
  ASSERT_EQ(Pdvo("synth -o " + (dir / "s") + " -n 3 --seed 6 --set walk.fps=1 -v warning", dir).code, 0);
  const std::string model = PDVO_SOURCE_DIR "/models/default/model.yml";
  const CommandResult ok =
      Pdvo("detect -m " + model + " " + (dir / "s") + " -o " + (dir / "det") + " --overlay -v warning", dir);
  ASSERT_EQ(ok.code, 0) << ok.err;
  const cv::Mat stages = cv::imread(dir / "det/000001_stages.png");
  EXPECT_EQ(stages.size(), cv::Size(3 * 320, 2 * 240));  // six panels at the working size
  int planes = 0;
  for (const char* name : {"000000.json", "000001.json", "000002.json"}) {
    const std::string path = dir / ("det/" + std::string(name));
    const Annotation a = ReadAnnotation(path);
    for (const ValidationIssue& issue : Validate(a)) EXPECT_FALSE(issue.is_error) << name << ": " << issue.message;
    for (const AnnotationShape& shape : a.shapes) {
      if (!shape.IsPlane()) continue;
      ++planes;
      ASSERT_TRUE(shape.score.has_value());
      EXPECT_GE(*shape.score, 0.5);
    }
    EXPECT_TRUE(fs::exists(ResolveImagePath(a, path))) << name << ": the image path resolves";
  }
  EXPECT_GT(planes, 0);
  EXPECT_TRUE(fs::exists(dir / "det/detector.yaml"));
  ASSERT_EQ(Pdvo("detect -m " + model + " " + (dir / "s/rgb/000001.png") + " -c " + (dir / "s/camera.yaml") + " -o " +
                     (dir / "one") + " -v warning",
                 dir)
                .code,
            0);
  EXPECT_EQ(ReadFile(dir / "one/000001.json"), ReadFile(dir / "det/000001.json"));

  const auto expect_error = [&](const std::string& args, const std::string& text) { ExpectError(args, text, dir); };
  expect_error("detect -v warning -m " + model + " " + (dir / "gone.png") + " -o " + (dir / "o1"), "gone.png");
  fs::create_directories(dir / "empty");
  expect_error("detect -v warning -m " + model + " " + (dir / "empty") + " -o " + (dir / "o2"), "empty");
  expect_error("detect -v warning -m " + (dir / "s/camera.yaml") + " " + (dir / "s") + " -o " + (dir / "o3"),
               "camera.yaml");
  cv::imwrite(dir / "tiny.png", cv::Mat(20, 20, CV_8UC3, cv::Scalar(0, 0, 0)));
  expect_error(
      "detect -v warning -m " + model + " " + (dir / "tiny.png") + " -o " + (dir / "o4") + " --set window_sizes=400",
      "smaller than the smallest window");
  for (const char* o : {"o1", "o2", "o3", "o4"}) EXPECT_FALSE(fs::exists(dir / o)) << o << ": no partial output";
}

}  // namespace
}  // namespace pdvo

namespace pdvo {
namespace {

// A small end-to-end run: train on one generated street, evaluate on another (a seed not used in training).
TEST(Cli, TrainAndEvaluateOnGeneratedStreets) {
  test::TempDir dir;
  const std::string frames = " -n 40 --set walk.fps=3 -v warning";
  ASSERT_EQ(Pdvo("synth -o " + (dir / "train") + " --seed 11" + frames, dir).code, 0);
  ASSERT_EQ(Pdvo("synth -o " + (dir / "test") + " --seed 12 -n 20 --set walk.fps=3 -v warning", dir).code, 0);
  const std::string small =
      " --set gradient_words=60 --set colour_words=16 --set topics.topics=8 --set vocabulary_samples=5000"
      " --set max_regions_per_class=120 --set max_normal_regions=120 --set rvm.gammas=0.5 --cv 2 -v warning";
  const CommandResult t = Pdvo("train -a " + (dir / "train/annotations") + " -o " + (dir / "m.yml") + small, dir);
  ASSERT_EQ(t.code, 0) << t.err;
  EXPECT_NE(t.out.find("wrote"), std::string::npos);
  // The same seed gives the same model, byte for byte.
  ASSERT_EQ(Pdvo("train -a " + (dir / "train/annotations") + " -o " + (dir / "m2.yml") + small, dir).code, 0);
  EXPECT_EQ(ReadFile(dir / "m.yml"), ReadFile(dir / "m2.yml"));
  // The default committee of classifiers, each trained on its own draw of regions.
  const PlaneModel model = PlaneModel::Read(dir / "m.yml");
  ASSERT_EQ(model.classifiers.size(), 15u);
  for (size_t i = 1; i < model.classifiers.size(); ++i) {
    const RvmFunction &a = model.classifiers[0].rvm, &b = model.classifiers[i].rvm;
    EXPECT_FALSE(a.size() == b.size() && a.vectors == b.vectors) << "classifiers 0 and " << i << " are the same";
  }
  // Each word's plane log-odds, counted over the training points: some words lean to planes, some (leaves, sky) away.
  ASSERT_EQ(model.word_plane_log_odds.size(), 60 + 16);
  EXPECT_LT(model.word_plane_log_odds.minCoeff(), -1);
  EXPECT_GT(model.word_plane_log_odds.maxCoeff(), 0.1);
  // Counted again for the trained model (as for a model trained before them): the same log-odds, the classifiers
  // untouched, and the card says where they came from.
  const CommandResult prior = Pdvo("train --word-prior-of " + (dir / "m.yml") + " -a " + (dir / "train/annotations") +
                                       " -o " + (dir / "m3.yml") + " -v warning",
                                   dir);
  ASSERT_EQ(prior.code, 0) << prior.err;
  const PlaneModel recounted = PlaneModel::Read(dir / "m3.yml");
  EXPECT_TRUE(recounted.word_plane_log_odds.isApprox(model.word_plane_log_odds, 1e-12));
  EXPECT_EQ(recounted.classifiers[0].rvm.vectors, model.classifiers[0].rvm.vectors);
  EXPECT_NE(recounted.card.word_prior.find("train/annotations (40 files; pdvo "), std::string::npos)
      << recounted.card.word_prior;

  const CommandResult e = Pdvo("evaluate -m " + (dir / "m.yml") + " -a " + (dir / "test/annotations") + " --json " +
                                   (dir / "report.json") + " -v warning",
                               dir);
  ASSERT_EQ(e.code, 0) << e.err;
  const nlohmann::json report = nlohmann::json::parse(ReadFile(dir / "report.json"));
  const nlohmann::json& overall = report["overall"];
  EXPECT_GT(overall["regions"].get<int>(), 100);
  EXPECT_EQ(report["per_image"].size(), 20u);
  // Chance is 0.5 balanced accuracy. One constant normal (the training planes' mean) is off by 58 degrees on
  // average on held-out streets (seeds 201-202 against 101-104, 3 fps, measured over the annotated planes).
  EXPECT_GT(overall["balanced_accuracy"].get<double>(), 0.85) << e.out;
  EXPECT_GT(overall["roc_auc"].get<double>(), 0.9) << e.out;
  EXPECT_LT(overall["normal_error_deg"]["mean"].get<double>(), 35) << e.out;
  // Per region: as many as the image's metrics count, with a box and, for planes, both normals; the regions'
  // normals reproduce the overall mean error.
  double error_sum = 0;
  int normals = 0, regions = 0;
  for (const nlohmann::json& image : report["per_image"]) {
    EXPECT_EQ(image["regions"].size(), image["metrics"]["regions"].get<size_t>());
    for (const nlohmann::json& r : image["regions"]) {
      ++regions;
      EXPECT_EQ(r["box"].size(), 4u);
      EXPECT_GT(r["box"][2].get<int>(), 0);
      if (!r.contains("true_normal")) continue;
      const Eigen::Vector3d n(r["normal"][0], r["normal"][1], r["normal"][2]);
      const Eigen::Vector3d t(r["true_normal"][0], r["true_normal"][1], r["true_normal"][2]);
      error_sum += AngleDeg(n, t);
      ++normals;
    }
  }
  EXPECT_EQ(regions, overall["regions"].get<int>());
  ASSERT_GT(normals, 0);
  EXPECT_NEAR(error_sum / normals, overall["normal_error_deg"]["mean"].get<double>(), 1e-6);

  // The same model without the vanishing-direction fusion (the option edited in the file): the same regions and
  // accuracy (the fusion leaves the classifier alone), and normals further from the truth.
  std::string text = ReadFile(dir / "m.yml");
  const size_t fuse = text.find("fuse_normals: true");
  ASSERT_NE(fuse, std::string::npos);
  text.replace(fuse, 18, "fuse_normals: false");
  WriteFileAtomically(dir / "unfused.yml", text);  // the edit without a new checksum is refused, naming the file
  ExpectError("evaluate -m " + (dir / "unfused.yml") + " -a " + (dir / "test/annotations"),
              "unfused.yml: checksum mismatch", dir);
  WriteFileAtomically(dir / "unfused.yml", SealModelText(text));
  const CommandResult u = Pdvo("evaluate -m " + (dir / "unfused.yml") + " -a " + (dir / "test/annotations") +
                                   " --json " + (dir / "unfused.json") + " -v warning",
                               dir);
  ASSERT_EQ(u.code, 0) << u.err;
  const nlohmann::json unfused = nlohmann::json::parse(ReadFile(dir / "unfused.json"))["overall"];
  EXPECT_EQ(unfused["regions"], overall["regions"]);
  EXPECT_EQ(unfused["accuracy"], overall["accuracy"]);
  EXPECT_LT(overall["normal_error_deg"]["mean"].get<double>(), unfused["normal_error_deg"]["mean"].get<double>())
      << e.out << u.out;
  // evaluate --no-fusion is that edit.
  const CommandResult nf = Pdvo("evaluate -m " + (dir / "m.yml") + " -a " + (dir / "test/annotations") +
                                    " --no-fusion --json " + (dir / "nofusion.json") + " -v warning",
                                dir);
  ASSERT_EQ(nf.code, 0) << nf.err;
  EXPECT_EQ(nlohmann::json::parse(ReadFile(dir / "nofusion.json"))["overall"], unfused);

  // The other learners in the RVM's place, on the same street: each beats chance by a wide margin and names
  // itself in the file.
  for (const char* learner : {"svm", "knn", "trees"}) {
    SCOPED_TRACE(learner);
    const std::string model = dir / (std::string(learner) + ".yml"), json = dir / (std::string(learner) + ".json");
    const CommandResult lt =
        Pdvo("train -a " + (dir / "train/annotations") + " -o " + model + " --classifier " + learner + small, dir);
    ASSERT_EQ(lt.code, 0) << lt.err;
    EXPECT_EQ(OptionName(PlaneModel::Read(model).learner()), learner);
    const CommandResult le =
        Pdvo("evaluate -m " + model + " -a " + (dir / "test/annotations") + " --json " + json + " -v warning", dir);
    ASSERT_EQ(le.code, 0) << le.err;
    const nlohmann::json o = nlohmann::json::parse(ReadFile(json))["overall"];
    EXPECT_GT(o["balanced_accuracy"].get<double>(), 0.8) << le.out;
    EXPECT_LT(o["normal_error_deg"]["mean"].get<double>(), 35) << le.out;
  }
}

TEST(Cli, TrainAndEvaluateRejectBadInputs) {
  test::TempDir dir;
  const auto expect_error = [&](const std::string& args, const std::string& text) { ExpectError(args, text, dir); };
  fs::create_directories(dir / "empty");
  expect_error("train -a " + (dir / "empty") + " -o " + (dir / "m.yml"), "empty");
  // One image, planes only: no non-plane examples.
  cv::Mat image(120, 160, CV_8UC3);
  cv::randu(image, 0, 255);
  fs::create_directories(dir / "planes");
  WriteImage(dir / "planes/img.png", image);
  Annotation a = test::ImageAnnotation("img.png", 160, 120,
                                       {test::RectShape(kPlaneLabel, 5, 5, 150, 110, Eigen::Vector3d(0, 0, -1))});
  WriteAnnotation(dir / "planes/a.json", a);
  expect_error("train -a " + (dir / "planes") + " -o " + (dir / "m.yml") + " --set recogniser.working_width=0 -v error",
               "no non-plane regions");
  expect_error("train -a " + (dir / "planes") + " -o " + (dir / "m.yml") + " --set classifiers=0",
               "invalid train options: classifiers >= 1 does not hold (classifiers = 0)");
  expect_error("train -a " + (dir / "planes") + " -o " + (dir / "m.yml") + " --classifier forest",
               "--classifier: forest not in {rvm,svm,knn,trees}");
  expect_error("train -a " + (dir / "planes") + " -o " + (dir / "m.yml") + " --set classifier=forest",
               "'forest' is not one of rvm, svm, knn, trees");
  // A missing image.
  a.image_path = "gone.png";
  fs::create_directories(dir / "missing");
  WriteAnnotation(dir / "missing/a.json", a);
  expect_error("train -a " + (dir / "missing") + " -o " + (dir / "m.yml") + " -v error", "gone.png: file not found");
  EXPECT_FALSE(fs::exists(dir / "m.yml"));
  // A model of another version.
  WriteFileAtomically(dir / "old.yml", "%YAML:1.0\n---\nformat: pdvo-plane-model\nversion: 0\n");
  expect_error("evaluate -m " + (dir / "old.yml") + " -a " + (dir / "planes"), "model version 0");
}

}  // namespace
}  // namespace pdvo
