// Annotation from depth: finds the planes in a depth map and writes them as `plane` shapes with their normals,
// and large clearly non-planar regions as `non-plane` shapes. Turns any RGB-D dataset into training data.
//
// Method, at a working resolution (default 320 px wide):
//  1. Back-project the depth through the (distorted) camera; fit a plane to each pixel's (2r+1)^2
//     neighbourhood from box-filtered moments, giving a local normal and RMS residual.
//  2. Depth noise grows with depth: sigma(z) = a + b (z - z0)^2 (Nguyen, Izadi & Lovell 2012, for Kinect).
//  3. Region growing from the flattest seeds: a neighbour joins a plane if its point lies within
//     `inlier_sigmas` sigma(z) of the plane and its local normal within `max_normal_angle_deg`; the plane is
//     refitted as the region doubles. Pixels along the regions' edges, whose windows straddle the edge, then
//     go to the neighbouring plane they fit best. Adjacent regions of one surface (sensors bend large planes
//     a little, which stops growth) are merged if their normals agree and their seam fits both planes.
//     A final weighted least-squares fit on pixels with flat windows gives each plane's normal.
//  4. Regions above `min_plane_fraction` of the image become polygons: small holes are filled, larger ones
//     are joined to the outside by a narrow cut (a "keyhole") so that the polygon leaves them out.
//  5. Clearly non-planar pixels, outside every plane: a local residual above `nonplanar_residual` sigma(z)
//     (rough at the window's scale), or local normals that disagree over a window twice as wide, 1 - |mean
//     normal| above `nonplanar_dispersion` (bumpy or curved at a larger scale: foliage, round objects).
//     Grouped into blobs that keep clear of the planes, large ones become `non-plane` shapes.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pdvo/annotations/annotation.h"
#include "pdvo/annotations/mask_polygons.h"
#include "pdvo/common/camera.h"

namespace pdvo {

struct DepthPlaneOptions {
  int working_width = 320;              // px; depth is processed at this width
  double min_depth = 0.1;               // m; nearer readings are ignored
  double max_depth = 6.0;               // m; farther readings are ignored
  int normal_radius = 4;                // px at working width; local fits use (2r+1)^2 windows
  double noise_a = 0.0012;              // m; sigma(z) = a + b (z - z0)^2
  double noise_b = 0.0019;              // 1/m
  double noise_z0 = 0.4;                // m
  double inlier_sigmas = 5.0;           // point-to-plane threshold, in sigma(z)
  double max_normal_angle_deg = 20.0;   // local normal vs plane normal, degrees
  double seed_max_residual = 1.5;       // seeds' local RMS residual, in sigma(z)
  double merge_angle_deg = 5.0;         // adjacent regions with normals this close may merge, degrees
  double min_plane_fraction = 0.015;    // of the image area
  double nonplanar_residual = 2.5;      // local RMS residual above which a pixel is non-planar, in sigma(z)
  double nonplanar_dispersion = 0.1;    // 1 - |mean local normal| above which a pixel is non-planar
  double min_nonplane_fraction = 0.02;  // of the image area
  double min_hole_fraction = 0.003;     // holes in a region larger than this are cut out, of the image area
  double polygon_epsilon = 1.0;         // px at full resolution (Douglas-Peucker tolerance)

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("working_width", self.working_width);
    visit("min_depth", self.min_depth);
    visit("max_depth", self.max_depth);
    visit("normal_radius", self.normal_radius);
    visit("noise_a", self.noise_a);
    visit("noise_b", self.noise_b);
    visit("noise_z0", self.noise_z0);
    visit("inlier_sigmas", self.inlier_sigmas);
    visit("max_normal_angle_deg", self.max_normal_angle_deg);
    visit("seed_max_residual", self.seed_max_residual);
    visit("merge_angle_deg", self.merge_angle_deg);
    visit("min_plane_fraction", self.min_plane_fraction);
    visit("nonplanar_residual", self.nonplanar_residual);
    visit("nonplanar_dispersion", self.nonplanar_dispersion);
    visit("min_nonplane_fraction", self.min_nonplane_fraction);
    visit("min_hole_fraction", self.min_hole_fraction);
    visit("polygon_epsilon", self.polygon_epsilon);
  }
  bool Check() const;
  bool operator==(const DepthPlaneOptions&) const = default;
};

// A plane found in a depth map: its mask (at working resolution) and unit normal (camera frame, towards the
// camera), with the plane's offset and fit quality.
struct DepthPlane : PlaneMask {
  double distance = 0;    // m; the plane is normal . x + distance = 0 (distance > 0)
  double rms_sigmas = 0;  // RMS point-to-plane residual, in sigma(z)
};

class DepthPlaneFinder {
 public:
  // `camera` is the depth map's camera (registered to the colour image); throws InvalidArgument for bad
  // options.
  DepthPlaneFinder(const Camera& camera, const DepthPlaneOptions& options);

  // Planes (largest first) and the non-planar mask, at working resolution. `depth` is CV_32F metres (0 =
  // unknown) of the camera's size; throws InvalidArgument otherwise.
  std::vector<DepthPlane> FindPlanes(const cv::Mat& depth, cv::Mat* nonplanar_mask = nullptr) const;

  // The annotation of one frame: planes, then non-planes. `image_path` is written as the imagePath.
  Annotation Annotate(const cv::Mat& depth, const std::string& image_path) const;

  // The resolution the depth is processed at.
  cv::Size working_size() const { return ray_x_.size(); }

 private:
  Camera camera_;
  DepthPlaneOptions options_;
  cv::Mat source_x_, source_y_;  // CV_32S: the full-resolution pixel each working pixel samples
  cv::Mat ray_x_, ray_y_;        // CV_64F: its viewing ray (x, y, 1)
};

}  // namespace pdvo
