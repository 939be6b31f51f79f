#include "pdvo/sim/synth.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pdvo/annotations/mask_polygons.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/options.h"
#include "pdvo/common/trajectory.h"

namespace pdvo::sim {

bool SynthOptions::Check() const {
  PDVO_CHECK_OPTION(width >= 32 && height >= 24 && width <= 8192 && height <= 8192);
  PDVO_CHECK_OPTION(fx >= 0 && fy >= 0);
  return street.Check() && walk.Check() && render.Check();
}

Camera SynthOptions::MakeCamera() const {
  Camera c = Camera::WithFieldOfView(width, height, 60);
  if (fx > 0) c.fx = c.fy = fx;
  if (fy > 0) c.fy = fy;
  if (cx >= 0) c.cx = cx;
  if (cy >= 0) c.cy = cy;
  return c;
}

Annotation AnnotateFrame(const Street& street, const RenderedFrame& frame, const Rigid3d& world_from_cam,
                         const Camera& camera, const std::string& image_path) {
  Annotation a;
  a.image_path = image_path;
  a.image_width = camera.width;
  a.image_height = camera.height;
  a.camera = camera.Undistorted();  // the format holds pinhole intrinsics
  // Visible planes, by pixel count, largest first.
  std::vector<int> count(street.planes.size(), 0);
  cv::Mat grouped(frame.id.size(), CV_32S, cv::Scalar(-1));
  for (int i = 0; i < static_cast<int>(frame.id.total()); ++i) {
    const int id = frame.id.at<int>(i);
    if (id < 0) continue;
    // Coplanar polygons (the road and pavements, say) are one plane.
    const int surface = street.planes[id].surface;
    grouped.at<int>(i) = surface;
    ++count[surface];
  }
  std::vector<int> visible;
  for (size_t id = 0; id < count.size(); ++id) {
    if (count[id] > 0) visible.push_back(static_cast<int>(id));
  }
  std::stable_sort(visible.begin(), visible.end(), [&](int x, int y) { return count[x] > count[y]; });
  const Eigen::Quaterniond cam_from_world = world_from_cam.rotation.conjugate();
  std::vector<PlaneMask> planes;
  for (int id : visible) {
    PlaneMask p;
    p.mask = grouped == id;
    p.normal = cam_from_world * street.planes[id].normal;
    planes.push_back(std::move(p));
  }
  MaskPolygonOptions options;
  options.min_plane_pixels = options.min_nonplane_pixels = 30;
  options.min_hole_pixels = 20;
  options.epsilon_full_px = 0.7;
  AddShapesFromMasks(planes, frame.id < 0, options, &a);
  return a;
}

namespace {
std::string FrameName(int i) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d", i);
  return buf;
}

nlohmann::json PlanesJson(const Street& street) {
  nlohmann::json planes = nlohmann::json::array();
  for (const WorldPlane& p : street.planes) {
    nlohmann::json polygon = nlohmann::json::array();
    for (const auto& x : p.polygon) polygon.push_back({x.x(), x.y(), x.z()});
    planes.push_back({{"id", p.id},
                      {"material", MaterialName(p.material)},
                      {"normal", {p.normal.x(), p.normal.y(), p.normal.z()}},
                      {"distance", p.distance},
                      {"surface", p.surface},
                      {"polygon", polygon}});
  }
  return {{"frame", "world: y down, ground y = 0; plane: normal . x + distance = 0, normal facing the street"},
          {"planes", planes}};
}

// Poses during the exposure of frame i, ending at its own pose (motion blur).
std::vector<Rigid3d> ExposurePoses(const Trajectory& walk, int i, const RenderOptions& o) {
  if (o.motion_blur_samples <= 1 || i == 0) return {walk[i].world_from_cam};
  std::vector<Rigid3d> poses;
  const Rigid3d& a = walk[i - 1].world_from_cam;
  const Rigid3d& b = walk[i].world_from_cam;
  for (int k = 0; k < o.motion_blur_samples; ++k) {
    const double f = 1.0 - o.exposure_fraction * (o.motion_blur_samples - 1 - k) / (o.motion_blur_samples - 1);
    poses.emplace_back(a.rotation.slerp(f, b.rotation), a.translation + f * (b.translation - a.translation));
  }
  return poses;
}
}  // namespace

WalkedStreet MakeWalkedStreet(const SynthOptions& options, int frames, uint64_t seed) {
  WalkedStreet out;
  out.street = GenerateStreet(options.street, options.walk.speed * frames / options.walk.fps + 30.0, seed);
  out.walk = WalkStreet(out.street, options.walk, frames, seed);
  return out;
}

Annotation AnnotateView(const Renderer& renderer, const Rigid3d& world_from_cam) {
  RenderedFrame geometry;
  renderer.RenderGeometry(world_from_cam, &geometry);
  return AnnotateFrame(renderer.street(), geometry, world_from_cam, renderer.camera(), "");
}

void WriteSynthSequence(const std::string& out_dir, uint64_t seed, int frames, const SynthOptions& options,
                        const std::function<void()>& on_frame) {
  CheckOptionsOrThrow(options, "synth options");
  PDVO_THROW_CHECK(frames > 0, InvalidArgument, "synth: --frames must be positive, got " << frames);
  Camera camera = options.MakeCamera();
  camera.depth_scale = kSynthDepthScale;
  const auto [street, walk] = MakeWalkedStreet(options, frames, seed);
  const Renderer renderer(street, camera, options.render, seed);

  StagedOutputDir out(out_dir);
  SaveOptions(out.path("synth.yaml"), options, "synth");
  camera.Write(out.path("camera.yaml"));
  WriteFileAtomically(out.path("planes.json"), PlanesJson(street).dump(1) + "\n");
  std::string rgb_list = "# color images\n# timestamp filename\n",
              depth_list = "# depth maps (2000 per metre, see camera.yaml)\n# timestamp filename\n";
  RenderedFrame frame;
  cv::Mat depth16, ids16;
  for (int i = 0; i < frames; ++i) {
    renderer.Render(ExposurePoses(walk, i, options.render), walk[i].timestamp, static_cast<uint64_t>(i), &frame);
    const std::string name = FrameName(i);
    WriteImage(out.path("rgb/" + name + ".png"), frame.image);
    // Depth in half millimetres; what does not fit (beyond 32.7 m) is unknown, like sky.
    frame.depth.convertTo(depth16, CV_32F, kSynthDepthScale);
    depth16.setTo(0, depth16 > 65535.0);
    depth16.convertTo(depth16, CV_16U);
    WriteImage(out.path("depth/" + name + ".png"), depth16);
    frame.id.convertTo(ids16, CV_32S, 1, 1);
    ids16.setTo(0, ids16 < 0);
    ids16.convertTo(ids16, CV_16U);
    WriteImage(out.path("planes/" + name + ".png"), ids16);
    WriteAnnotation(out.path("annotations/" + name + ".json"),
                    AnnotateFrame(street, frame, walk[i].world_from_cam, camera, "../rgb/" + name + ".png"));
    char line[96];
    std::snprintf(line, sizeof(line), "%.6f rgb/%s.png\n", walk[i].timestamp, name.c_str());
    rgb_list += line;
    std::snprintf(line, sizeof(line), "%.6f depth/%s.png\n", walk[i].timestamp, name.c_str());
    depth_list += line;
    if (on_frame) on_frame();
  }
  WriteFileAtomically(out.path("rgb.txt"), rgb_list);
  WriteFileAtomically(out.path("depth.txt"), depth_list);
  WriteTrajectory(out.path("groundtruth.txt"), walk, TrajectoryFormat::kTum);
  out.Commit();
}

}  // namespace pdvo::sim
