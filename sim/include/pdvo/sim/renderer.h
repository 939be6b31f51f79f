// Rendering a street: exact depth and object ids by z-buffered rasterisation of the planar polygons (depth
// from the plane equation at each pixel centre) and analytic ray casting of the non-planar objects; then
// deferred shading of procedural textures (brick, render, stone, windows with frames and reflections, doors,
// shop signs, asphalt with markings, paving, leaves) lit by a sun and ambient light, with sensor noise,
// optional exposure changes and optional motion blur. The camera is an ideal pinhole.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/common/camera.h"
#include "pdvo/common/geometry.h"
#include "pdvo/sim/street.h"

namespace pdvo::sim {

struct RenderOptions {
  double noise_sigma = 2.0;         // grey levels of Gaussian sensor noise
  double exposure_variation = 0.0;  // relative amplitude of slow exposure changes (0: none)
  int motion_blur_samples = 1;      // >1: average this many renders over the exposure
  double exposure_fraction = 0.5;   // exposure time as a fraction of the frame interval (motion blur)
  double texels_per_metre = 25.0;   // texture resolution
  // >1: each pixel averages supersampling^2 rays (rendered at that multiple of the size, then INTER_AREA), as a
  // camera's pixel integrates the light over its area; 1: one ray through the pixel's centre (aliased edges).
  int supersampling = 1;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("noise_sigma", self.noise_sigma);
    visit("exposure_variation", self.exposure_variation);
    visit("motion_blur_samples", self.motion_blur_samples);
    visit("exposure_fraction", self.exposure_fraction);
    visit("texels_per_metre", self.texels_per_metre);
    visit("supersampling", self.supersampling);
  }
  bool Check() const;
  bool operator==(const RenderOptions&) const = default;
};

// Ids in RenderedFrame::id: a plane's id (>= 0), kSkyId, or BlobLabel(blob id).
inline constexpr int kSkyId = -1;
inline int BlobLabel(int blob_id) { return -2 - blob_id; }

struct RenderedFrame {
  cv::Mat image;  // CV_8UC3, BGR
  cv::Mat depth;  // CV_32F, z in metres along the optical axis; 0 for sky
  cv::Mat id;     // CV_32S, see above
};

class Renderer {
 public:
  // Builds the textures (once). `street` is referenced, not copied: it must outlive the renderer. Throws
  // InvalidArgument for a camera with distortion or bad options.
  Renderer(const Street& street, const Camera& camera, const RenderOptions& options, uint64_t seed);

  // Depth and ids only: exact and fast.
  void RenderGeometry(const Rigid3d& world_from_cam, RenderedFrame* out) const;
  // Depth, ids and the shaded image at `time` (seconds; for exposure changes and noise). With motion blur,
  // `exposure_poses` are the poses during the exposure (the last is the frame's pose, which gives depth and
  // ids); otherwise pass just the frame's pose.
  void Render(const std::vector<Rigid3d>& exposure_poses, double time, uint64_t frame_index, RenderedFrame* out) const;

  const Camera& camera() const { return camera_; }
  const Street& street() const { return street_; }

 private:
  void Shade(const Rigid3d& world_from_cam, const RenderedFrame& geometry, cv::Mat* colour) const;
  void SetRays();  // ray_x_ and ray_y_ from camera_

  const Street& street_;
  Camera camera_;
  RenderOptions options_;
  std::vector<cv::Mat> textures_;      // per plane, CV_8UC3, row 0 at the top of the plane
  std::vector<double> plane_light_;    // per plane: ambient + diffuse sun
  Eigen::Vector3d sun_;                // unit, world, towards the sun
  cv::Mat noise_;                      // CV_32F table of N(0, 1) samples
  std::vector<double> ray_x_, ray_y_;  // per column / row: pinhole ray (x, y, 1)
  double exposure_phase_;
  std::shared_ptr<const Renderer> fine_;  // supersampling > 1: the same street at that multiple of the size
};

}  // namespace pdvo::sim
