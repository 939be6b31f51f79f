#include "pdvo/sim/synth.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/depth_planes.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/dataset.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/geometry.h"
#include "pdvo/common/options.h"
#include "pdvo/eval/plane_match.h"
#include "pdvo/test/support.h"

namespace pdvo::sim {
namespace {
namespace fs = std::filesystem;

struct Scene {
  SynthOptions options;
  Camera camera;
  Street street;
  Trajectory walk;
  explicit Scene(uint64_t seed, int frames = 120, bool loop = false) {
    options.street.loop = loop;
    camera = options.MakeCamera();
    WalkedStreet walked = MakeWalkedStreet(options, frames, seed);
    street = std::move(walked.street);
    walk = std::move(walked.walk);
  }
};

// Reprojects frame a's plane pixels into frame b; where the landing point's four neighbours show the same plane,
// compares the predicted depth with b's depth there (inverse depth interpolated, which is exact on a plane).
// Returns the largest error in metres; *compared counts the pixels.
double ReprojectionError(const Camera& cam, const RenderedFrame& a, const Rigid3d& pose_a, const RenderedFrame& b,
                         const Rigid3d& pose_b, int* compared) {
  const Rigid3d b_from_a = pose_b.Inverse() * pose_a;
  double worst = 0;
  *compared = 0;
  for (int v = 0; v < cam.height; v += 2) {
    for (int u = 0; u < cam.width; u += 2) {
      const int id = a.id.at<int>(v, u);
      if (id < 0) continue;
      const double z = a.depth.at<float>(v, u);
      const Eigen::Vector3d x = b_from_a * Eigen::Vector3d(z * (u - cam.cx) / cam.fx, z * (v - cam.cy) / cam.fy, z);
      if (x.z() < 0.1) continue;
      const double pu = cam.fx * x.x() / x.z() + cam.cx, pv = cam.fy * x.y() / x.z() + cam.cy;
      const int u0 = static_cast<int>(std::floor(pu)), v0 = static_cast<int>(std::floor(pv));
      if (u0 < 0 || v0 < 0 || u0 + 1 >= cam.width || v0 + 1 >= cam.height) continue;
      bool same = true;
      double inv = 0;
      const double fu = pu - u0, fv = pv - v0;
      for (int dv = 0; dv < 2; ++dv) {
        for (int du = 0; du < 2; ++du) {
          same = same && b.id.at<int>(v0 + dv, u0 + du) == id;
          inv += (du ? fu : 1 - fu) * (dv ? fv : 1 - fv) / b.depth.at<float>(v0 + dv, u0 + du);
        }
      }
      if (!same) continue;  // occluded, or at the plane's edge
      worst = std::max(worst, std::abs(1.0 / inv - x.z()));
      ++*compared;
    }
  }
  return worst;
}

TEST(Synth, DepthReprojectsExactlyBetweenFrames) {
  const Scene s(3);
  const Renderer renderer(s.street, s.camera, s.options.render, 3);
  for (const auto& [i, k] : {std::pair{10, 1}, std::pair{10, 15}, std::pair{60, 45}}) {
    RenderedFrame a, b;
    renderer.RenderGeometry(s.walk[i].world_from_cam, &a);
    renderer.RenderGeometry(s.walk[i + k].world_from_cam, &b);
    int compared = 0;
    const double worst =
        ReprojectionError(s.camera, a, s.walk[i].world_from_cam, b, s.walk[i + k].world_from_cam, &compared);
    EXPECT_GT(compared, 3000) << i << "->" << i + k;
    EXPECT_LT(worst, 1e-3) << i << "->" << i + k;
  }
}

// A pixel that averages its area (render.supersampling) changes little when the image moves by half a pixel;
// one ray through its centre makes thin edges jump from pixel to pixel (aliasing). The camera turns by half a
// pixel; the second frame, moved back by half a pixel (bilinear), is compared with the first near the image
// centre. Depth and ids are the same either way.
TEST(Synth, SupersamplingAveragesEachPixelsArea) {
  const Scene s(5);
  RenderOptions point = s.options.render;
  point.noise_sigma = 0;
  RenderOptions area = point;
  area.supersampling = 2;
  const Rigid3d pose = s.walk[30].world_from_cam;
  Rigid3d turned = pose;
  turned.rotation = (pose.rotation * ExpSO3(Eigen::Vector3d(0, 0.5 / s.camera.fx, 0))).normalized();
  const Eigen::Vector3d ahead = pose * Eigen::Vector3d(0, 0, 10);
  const double shift = (s.camera.Project(turned.Inverse() * ahead) - s.camera.Project(pose.Inverse() * ahead)).x();
  ASSERT_NEAR(std::abs(shift), 0.5, 0.01);
  const cv::Rect centre(cvRound(s.camera.cx) - 60, 20, 120, s.camera.height - 40);
  std::map<int, double> difference;  // by supersampling: mean absolute grey difference
  std::map<int, RenderedFrame> first;
  for (const RenderOptions& options : {point, area}) {
    const Renderer renderer(s.street, s.camera, options, 5);
    RenderedFrame a, b;
    renderer.Render({pose}, 1.0, 30, &a);
    renderer.Render({turned}, 1.0, 30, &b);
    cv::Mat grey_a, grey_b, back;
    cv::cvtColor(a.image, grey_a, cv::COLOR_BGR2GRAY);
    cv::cvtColor(b.image, grey_b, cv::COLOR_BGR2GRAY);
    const cv::Mat move = (cv::Mat_<double>(2, 3) << 1, 0, -shift, 0, 1, 0);
    cv::warpAffine(grey_b, back, move, grey_b.size(), cv::INTER_LINEAR);
    cv::Mat diff;
    cv::absdiff(grey_a(centre), back(centre), diff);
    difference[options.supersampling] = cv::mean(diff)[0];
    first[options.supersampling] = a;
  }
  EXPECT_LT(difference[2], 0.7 * difference[1]) << difference[1] << " " << difference[2];
  EXPECT_EQ(cv::norm(first[1].depth, first[2].depth, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(first[1].id, first[2].id, cv::NORM_INF), 0);
  // The same light: the frames' mean grey levels agree.
  EXPECT_NEAR(cv::mean(first[1].image)[1], cv::mean(first[2].image)[1], 1.0);
}

TEST(Synth, AnnotationNormalsAgreeWithNormalsFromDepth) {
  const Scene s(4);
  const Renderer renderer(s.street, s.camera, s.options.render, 4);
  int checked = 0;
  double worst = 0;
  for (int i : {0, 50, 100}) {
    RenderedFrame f;
    const Rigid3d& pose = s.walk[i].world_from_cam;
    renderer.RenderGeometry(pose, &f);
    const Annotation a = AnnotateFrame(s.street, f, pose, s.camera, "x.png");
    ASSERT_TRUE(std::none_of(Validate(a).begin(), Validate(a).end(), [](const auto& issue) { return issue.is_error; }));
    for (const AnnotationShape& shape : a.shapes) {
      if (!shape.IsPlane()) continue;
      const cv::Mat mask = RasteriseShape(shape, a);
      // The plane under the polygon: the id most of its pixels show.
      std::map<int, int> votes;
      for (int p = 0; p < static_cast<int>(mask.total()); ++p) {
        if (mask.at<uchar>(p)) ++votes[f.id.at<int>(p)];
      }
      const int id =
          std::max_element(votes.begin(), votes.end(), [](auto& x, auto& y) { return x.second < y.second; })->first;
      ASSERT_GE(id, 0);
      if (votes[id] < 200) continue;
      // Least-squares plane through the back-projected depth of those pixels.
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      std::vector<Eigen::Vector3d> points;
      for (int p = 0; p < static_cast<int>(mask.total()); ++p) {
        if (!mask.at<uchar>(p) || f.id.at<int>(p) != id) continue;
        const int u = p % s.camera.width, v = p / s.camera.width;
        const double z = f.depth.at<float>(p);
        points.emplace_back(z * (u - s.camera.cx) / s.camera.fx, z * (v - s.camera.cy) / s.camera.fy, z);
        mean += points.back();
      }
      mean /= static_cast<double>(points.size());
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const auto& x : points) cov += (x - mean) * (x - mean).transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      Eigen::Vector3d n = eig.eigenvectors().col(0);
      if (n.dot(mean) > 0) n = -n;
      const double angle = AngleDeg(n, *shape.normal);
      EXPECT_LT(angle, 1.0) << "frame " << i << " plane " << id;
      worst = std::max(worst, angle);
      EXPECT_LT(shape.normal->dot(mean), 0.0);  // towards the camera
      ++checked;
    }
  }
  EXPECT_GE(checked, 15);
  std::printf("%d annotated planes: largest angle to the normal fitted to depth %.5f deg\n", checked, worst);
}

TEST(Synth, WalkMovesAtWalkingSpeedAndLoopsClose) {
  const Scene s(5, 300);
  const double length = PathLength(s.walk);
  EXPECT_NEAR(length / s.walk.back().timestamp, 1.4, 0.1);  // bob and sway add a little
  EXPECT_NEAR(s.walk[1].timestamp - s.walk[0].timestamp, 1 / 30.0, 1e-12);
  // Round a loop of about 100 m: the walk comes back to where it started.
  StreetOptions loop_options;
  loop_options.loop = true;
  const Street loop = GenerateStreet(loop_options, 100.0, 6);
  EXPECT_TRUE(loop.loop);
  const Trajectory walk = WalkStreet(loop, WalkOptions(), 4000, 6);
  const int lap = static_cast<int>(std::lround(loop.Length() / 1.4 * 30));
  ASSERT_LT(lap, 4000);
  EXPECT_LT((walk[lap].world_from_cam.translation - walk[0].world_from_cam.translation).norm(), 0.2);
}

TEST(Synth, SameSeedSameBytesAndTheTumReaderReadsIt) {
  test::TempDir dir;
  SynthOptions options;
  options.width = 160;
  options.height = 120;
  options.render.motion_blur_samples = 2;
  options.render.exposure_variation = 0.1;
  WriteSynthSequence(dir / "a", 9, 6, options);
  WriteSynthSequence(dir / "b", 9, 6, options);
  WriteSynthSequence(dir / "c", 10, 6, options);
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "a")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir / "a");
    EXPECT_EQ(ReadFile(e.path().string()), ReadFile((fs::path(dir / "b") / rel).string())) << rel;
    ++files;
  }
  EXPECT_EQ(files, 6 * 4 + 6 + 1);  // rgb, depth, planes, annotation per frame; 6 per sequence; the marker
  EXPECT_NE(ReadFile(dir / "a/rgb/000003.png"), ReadFile(dir / "c/rgb/000003.png"));

  auto sequence = OpenSequence(dir / "a");
  ASSERT_TRUE(sequence->camera().has_value());
  EXPECT_EQ(sequence->camera()->width, 160);
  const Trajectory gt = ReadTrajectory(dir / "a/groundtruth.txt", TrajectoryFormat::kTum);
  Frame frame;
  int n = 0;
  while (sequence->Next(&frame)) {
    ASSERT_FALSE(frame.depth.empty());
    ASSERT_TRUE(frame.world_from_cam.has_value());
    EXPECT_LT((frame.world_from_cam->translation - gt[n].world_from_cam.translation).norm(), 1e-6);
    ++n;
  }
  EXPECT_EQ(n, 6);
  EXPECT_TRUE(fs::exists(dir / "a/planes.json"));
  EXPECT_TRUE(Validate(ReadAnnotation(dir / "a/annotations/000005.json")).empty());
}

TEST(Synth, DepthFilesReprojectWithinAMillimetre) {
  test::TempDir dir;
  SynthOptions options;
  WriteSynthSequence(dir.str(), 12, 12, options);
  auto sequence = OpenSequence(dir.str());
  std::vector<Frame> frames(12);
  for (Frame& f : frames) ASSERT_TRUE(sequence->Next(&f));
  const Camera camera = *sequence->camera();
  RenderedFrame a, b;
  for (auto [frame, out] : {std::pair{0, &a}, std::pair{11, &b}}) {
    out->depth = frames[frame].depth;
    cv::Mat ids = ReadImage(dir / ("planes/" + std::string(frame ? "000011" : "000000") + ".png"), cv::IMREAD_ANYDEPTH);
    ids.convertTo(out->id, CV_32S, 1, -1);
    out->id.setTo(-1, out->depth == 0);  // beyond the 16-bit range: unknown
  }
  int compared = 0;
  const double worst =
      ReprojectionError(camera, a, *frames[0].world_from_cam, b, *frames[11].world_from_cam, &compared);
  EXPECT_GT(compared, 3000);
  EXPECT_LT(worst, 1e-3);
}

// Looking around turns the gaze about the vertical and nothing else: the same walk, its yaw offset by up to
// look_deg, through the whole range within a minute (a period of at most 30 s).
TEST(Synth, LookingAroundTurnsOnlyTheGaze) {
  const Scene s(5, 1800);
  WalkOptions looking = s.options.walk;
  looking.look_deg = 60;
  const Trajectory walk = WalkStreet(s.street, looking, 1800, 5);
  ASSERT_EQ(walk.size(), s.walk.size());
  double largest = 0;
  for (size_t i = 0; i < walk.size(); ++i) {
    EXPECT_EQ(walk[i].world_from_cam.translation, s.walk[i].world_from_cam.translation);
    const Eigen::AngleAxisd turn(walk[i].world_from_cam.rotation * s.walk[i].world_from_cam.rotation.conjugate());
    if (turn.angle() < 1e-9) continue;
    EXPECT_NEAR(std::abs(turn.axis().y()), 1.0, 1e-9) << "frame " << i;
    largest = std::max(largest, turn.angle());
  }
  EXPECT_LE(largest, 60 * M_PI / 180 + 1e-9);
  EXPECT_GE(largest, 59 * M_PI / 180);
}

TEST(Synth, BadOptionsAreRejected) {
  test::TempDir dir;
  SynthOptions options;
  options.street.max_turn_deg = 120;
  EXPECT_THROW(WriteSynthSequence(dir / "x", 1, 3, options), InvalidArgument);
  options = SynthOptions();
  options.walk.look_deg = -1;
  EXPECT_THROW(WriteSynthSequence(dir / "x", 1, 3, options), InvalidArgument);
  options = SynthOptions();
  EXPECT_THROW(WriteSynthSequence(dir / "x", 1, 0, options), InvalidArgument);
  options.render.supersampling = 0;
  EXPECT_THROW(WriteSynthSequence(dir / "x", 1, 3, options), InvalidArgument);
  options = SynthOptions();
  Camera distorted = options.MakeCamera();
  distorted.distortion[0] = 0.1;
  const Scene s(1, 10);
  EXPECT_THROW(Renderer(s.street, distorted, options.render, 1), InvalidArgument);
}

}  // namespace
}  // namespace pdvo::sim

namespace pdvo::sim {
namespace {

// The two parts check each other: annotation from depth, run on a synthetic sequence with the shipped options
// for its sensor, finds the planes of the exact annotations. Piece by piece (group_id cleared): the stored depth
// ends at 32.8 m, so a facade's far pieces lie beyond it, and the whole plane could not be matched.
TEST(Synth, AnnotateDepthRecoversTheStreetsPlanes) {
  const Scene s(21, 150);
  const Renderer renderer(s.street, s.camera, s.options.render, 21);
  const DepthPlaneFinder finder(
      s.camera, LoadOptions<DepthPlaneOptions>(PDVO_SOURCE_DIR "/annotations/config/synthetic.yaml", "annotate_depth"));
  std::vector<PlaneComparison> comparisons;
  std::vector<double> ious;
  double worst_angle = 0;
  for (int i = 0; i < 150; i += 15) {
    RenderedFrame f;
    renderer.RenderGeometry(s.walk[i].world_from_cam, &f);
    cv::Mat depth = f.depth.clone();
    depth.setTo(0, depth > 65535 / kSynthDepthScale);  // as stored
    Annotation truth = AnnotateFrame(s.street, f, s.walk[i].world_from_cam, s.camera, "x.png");
    Annotation found = finder.Annotate(depth, "x.png");
    for (Annotation* a : {&truth, &found}) {
      for (AnnotationShape& shape : a->shapes) shape.group_id.reset();
    }
    const PlaneComparison c = ComparePlanes(truth, found);
    for (const PlaneMatch& m : c.matches) {
      ious.push_back(m.iou);
      worst_angle = std::max(worst_angle, m.normal_angle_deg);
    }
    comparisons.push_back(c);
  }
  const PlaneComparisonSummary summary = Summarise(comparisons);
  std::sort(ious.begin(), ious.end());
  ASSERT_GE(ious.size(), 40u);
  EXPECT_GT(ious[ious.size() / 2], 0.9);  // median IoU of matched planes
  EXPECT_GT(ious[ious.size() / 4], 0.8);  // three quarters of them above 0.8
  EXPECT_LT(worst_angle, 2.0);
  std::printf(
      "annotate-depth on a synthetic street: %d of %d planes matched, IoU median %.3f, lower quartile %.3f, "
      "worst normal %.4f deg\n",
      summary.matched, summary.reference_planes, ious[ious.size() / 2], ious[ious.size() / 4], worst_angle);
}

TEST(Synth, ShippedDefaultConfigEqualsTheDefaults) {
  EXPECT_EQ(LoadOptions<SynthOptions>(PDVO_SOURCE_DIR "/sim/config/default.yaml", "synth"), SynthOptions());
}

// The driving option set drives as it says: 1 m a frame (10 m/s at 10 Hz along the centreline; the lane on the
// inside of a corner, the rounded corner itself and the street's start are shorter, the outside longer, by up to a
// fifth and a tenth), the camera at 1.65 m
// without steps, in the right-hand lane, and corners taken smoothly (a walker's +-2.5 m rounding would turn a
// car by many degrees in one frame).
TEST(Synth, DrivingConfigDrivesACar) {
  const SynthOptions o = LoadOptions<SynthOptions>(PDVO_SOURCE_DIR "/sim/config/driving.yaml", "synth");
  const Street street = GenerateStreet(o.street, 630, 201);
  // Per frame: the distance driven and the turn (degrees).
  const auto drive = [&](const WalkOptions& walk) {
    const Trajectory poses = WalkStreet(street, walk, 600, 201);
    std::vector<std::pair<double, double>> steps;
    for (size_t i = 1; i < poses.size(); ++i) {
      const Rigid3d& a = poses[i - 1].world_from_cam;
      const Rigid3d& b = poses[i].world_from_cam;
      EXPECT_NEAR(-b.translation.y(), walk.eye_height, 1e-9) << i;  // no steps
      steps.emplace_back((b.translation - a.translation).norm(), a.rotation.angularDistance(b.rotation) * 180 / M_PI);
    }
    return steps;
  };
  double path = 0, largest_turn = 0;
  for (const auto& [step, turn] : drive(o.walk)) {
    EXPECT_TRUE(step > 0.8 && step < 1.1) << step;
    path += step;
    largest_turn = std::max(largest_turn, turn);
  }
  EXPECT_GT(path, 0.95 * 599);
  EXPECT_LT(largest_turn, 3.0);
  WalkOptions sharp = o.walk;  // a walker's corners
  sharp.corner_smoothing = WalkOptions().corner_smoothing;
  double sharpest = 0;
  for (const auto& [step, turn] : drive(sharp)) sharpest = std::max(sharpest, turn);
  EXPECT_GT(sharpest, 2 * largest_turn);
  EXPECT_DOUBLE_EQ(o.walk.eye_height, 1.65);
  EXPECT_GT(o.walk.lateral_offset, 0);  // right of the centreline, inside the road
  EXPECT_LT(o.walk.lateral_offset, o.street.road_width / 2);
}

// The streets round a block are the default street closed into a loop, nothing else changed.
TEST(Synth, LoopConfigIsTheDefaultStreetClosed) {
  SynthOptions loop = LoadOptions<SynthOptions>(PDVO_SOURCE_DIR "/sim/config/loop.yaml", "synth");
  EXPECT_TRUE(loop.street.loop);
  loop.street.loop = SynthOptions().street.loop;
  EXPECT_EQ(loop, SynthOptions());
}

// The KITTI-view driving set is the driving set seen through KITTI's camera reduced to 320 px: the same street and
// drive (its other options repeat driving.yaml's and must not drift from them), 320x97 pixels and fx 184.6 px.
TEST(Synth, KittiViewConfigIsTheDrivingSetThroughKittisCamera) {
  SynthOptions kitti = LoadOptions<SynthOptions>(PDVO_SOURCE_DIR "/sim/config/driving_kitti.yaml", "synth");
  const SynthOptions driving = LoadOptions<SynthOptions>(PDVO_SOURCE_DIR "/sim/config/driving.yaml", "synth");
  EXPECT_EQ(kitti.width, 320);
  EXPECT_EQ(kitti.height, 97);
  EXPECT_NEAR(2 * std::atan(160 / kitti.fx) * 180 / M_PI, 81.8, 0.1);  // KITTI 06: 1226 px wide, fx 707.1 px
  kitti.width = driving.width;
  kitti.height = driving.height;
  kitti.fx = driving.fx;
  EXPECT_EQ(kitti, driving);
}

}  // namespace
}  // namespace pdvo::sim
