// The geometric cue to a vertical plane's orientation: where its horizontal edges vanish.
//
// Lines of one 3D direction d meet in the image at d's vanishing point, so the plane through the camera
// centre and any one of them has a normal m with m . d = 0. A straight edge at a pixel therefore constrains
// the direction of the 3D line it lies on. An image's coherent edges are found with the structure tensor; the
// near-vertical ones give the vertical direction (their planes all contain it). In a region, the remaining
// edges vote for the direction d = cos(phi) e1 + sin(phi) e2 of horizontal lines (e1, e2 spanning the
// horizontal plane), each with the robust (Cauchy) likelihood of its residual m . d. On a vertical plane, its
// normal is d x up. Edges near the horizon fit every phi and weigh nothing; edges that are not horizontal in
// 3D are outliers, bounded by the robust loss.
//
// The learned normal and this likelihood are fused per region (FuseNormal): planes the model calls horizontal
// snap to the vertical; for the others, phi maximises the model's prior (a von Mises density in 2 phi about the
// model's own azimuth) plus the edges' mean log-likelihood; either faces the camera. This assumes an upright
// man-made scene: planes are either horizontal or vertical. See models/README.md for what it gives.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pdvo/annotations/regions.h"
#include "pdvo/common/camera.h"

namespace pdvo {

struct VanishingOptions {
  bool fuse_normals = true;       // false: normals are the regressors' alone
  double field_of_view_deg = 60;  // horizontal field of view when the camera is not known
  double tensor_sigma = 1.5;      // px, the structure tensor's Gaussian window
  double min_strength = 5;        // an edge's gradient, grey levels per pixel (the tensor's larger root)
  double min_coherence = 0.4;     // ((l1 - l2) / (l1 + l2))^2 of the tensor's eigenvalues
  // Vertical edges: within this angle of the image's y axis when the vertical is found; in a region, those whose
  // line's plane is within this angle of containing the vertical (they say nothing of the azimuth).
  double vertical_band_deg = 30;
  double max_tilt_deg = 25;      // the vertical found must be this close to the image's y axis
  int min_edges = 20;            // per region (and 2.5x this per image for the vertical)
  int max_edges = 2000;          // per region: more are subsampled evenly
  double residual_scale = 0.4;   // Cauchy scale of m . d
  double prior_weight = 0.1;     // the model's von Mises concentration, against the mean log-likelihood
  double horizontal_cos = 0.85;  // |n . up| of the model's normal above this: a horizontal plane

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("fuse_normals", self.fuse_normals);
    visit("field_of_view_deg", self.field_of_view_deg);
    visit("tensor_sigma", self.tensor_sigma);
    visit("min_strength", self.min_strength);
    visit("min_coherence", self.min_coherence);
    visit("vertical_band_deg", self.vertical_band_deg);
    visit("max_tilt_deg", self.max_tilt_deg);
    visit("min_edges", self.min_edges);
    visit("max_edges", self.max_edges);
    visit("residual_scale", self.residual_scale);
    visit("prior_weight", self.prior_weight);
    visit("horizontal_cos", self.horizontal_cos);
  }
  bool Check() const;
  bool operator==(const VanishingOptions&) const = default;
};

// An image's coherent edges as the unit normals of their lines' planes through the camera centre.
struct EdgePlanes {
  Camera camera;                                  // the camera the planes were found with
  cv::Mat normals;                                // CV_32FC3, image-sized; zero where there is no coherent edge
  cv::Mat strength;                               // CV_32F, the edge's gradient (zero where none)
  Eigen::Vector3d up = Eigen::Vector3d::UnitY();  // the vertical in the camera frame (y down: pointing down)
  bool up_found = false;                          // false: too few vertical edges, or a tilt above max_tilt_deg
};
// `image`: 8-bit grey or BGR. `camera`: the image's, without distortion (an undistorted image's); without one,
// Camera::WithFieldOfView with the options' field of view. Throws InvalidArgument for another image type, or a
// camera that fails Camera::Check, has distortion or another image size.
EdgePlanes FindEdgePlanes(const cv::Mat& image, const std::optional<Camera>& camera, const VanishingOptions& options);

// A region's edges as constraints on the direction phi of horizontal lines, d(phi) = cos(phi) e1 + sin(phi) e2
// with phi in [0, pi): each edge's (m . e1, m . e2) and weight (its strength). Empty when the image has no
// vertical or the region has fewer than min_edges edges off the vertical band.
struct AzimuthLikelihood {
  Eigen::Vector3d up, e1, e2;
  std::vector<Eigen::Vector2f> constraints;
  std::vector<float> weights;
  double residual_scale = 1;
  double vertical_sin = 0;  // edges whose plane normal is this near the horizontal lie in the vertical band
  bool empty() const { return constraints.empty(); }
  // The edge whose plane has normal m (camera frame), with weight `strength`, as a constraint; false, and
  // nothing added, if it lies in the vertical band (a vertical line says nothing of phi).
  bool Add(const Eigen::Vector3f& m, float strength);
  // Each edge's robust loss log(1 + (m . d(phi) / scale)^2) for each phi: an edges x phis array.
  Eigen::ArrayXXf Losses(const std::vector<double>& phis) const;
  // For each phi, the weighted mean over edges of log(1 / (1 + (m . d(phi) / scale)^2)) (minus the Losses): at
  // most 0.
  std::vector<double> MeanLogLikelihoods(const std::vector<double>& phis) const;
  // The unit normal of the vertical plane whose horizontal lines run along d(phi), on the side of `towards`.
  Eigen::Vector3d Normal(double phi, const Eigen::Vector3d& towards) const;
  // The phi of the vertical plane nearest to the plane with normal n (n not along the vertical).
  double Phi(const Eigen::Vector3d& n) const;
};
AzimuthLikelihood RegionAzimuthLikelihood(const EdgePlanes& edges, const Region& region,
                                          const VanishingOptions& options);
// Without constraints: the image's vertical, the basis e1, e2 of the horizontal, the residual scale and the
// vertical band.
AzimuthLikelihood AzimuthBasis(const EdgePlanes& edges, const VanishingOptions& options);

// How much of a region lies on straight edges, a cue to man-made planes: the share of its pixels on coherent
// edges, and the share of their strength on vertical lines (see vertical_band_deg; without a vertical found, the
// image's y axis stands in for it). Zero for a region without pixels or edges.
Eigen::Vector2d EdgeStructure(const EdgePlanes& edges, const Region& region, const VanishingOptions& options);

// The ray through the centre of `region` (camera frame, z = 1).
Eigen::Vector3d RegionRay(const Camera& camera, const Region& region);

// The fused normal (see the top of this file); `model_normal` unit, camera frame. Without the fusion
// (fuse_normals false, no vertical found, too few edges), `model_normal`. Either way the result faces the camera
// at the region's centre (RegionRay with the edges' camera), as a seen plane does: a kept normal that faces away
// becomes the nearest one that faces the camera (edge-on to the ray).
Eigen::Vector3d FuseNormal(const Eigen::Vector3d& model_normal, const EdgePlanes& edges, const Region& region,
                           const VanishingOptions& options);

}  // namespace pdvo
