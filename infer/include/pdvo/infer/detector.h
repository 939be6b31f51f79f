// The plane detector (the paper's section III and Fig. 3): planes and their orientation in one image.
//   1. The image is described once (Recogniser::Describe) and overlapping windows of several sizes and shapes
//      are recognised from summed-area tables (window_features.h).
//   2. Each salient point's planarity is the median of the plane probabilities of the windows that contain it,
//      and its normal their probability-weighted robust mean on the sphere (sphere.h).
//   3. A Delaunay graph joins the points; its edges are weighted by distance and by colour contrast. MRF 1
//      labels points plane / non-plane (data: the planarity; a contrast-sensitive Potts term), exactly by a
//      graph cut; MRF 2 labels the planar points with orientations found by mean shift on their normals, by
//      alpha-expansion (mrf.h). Connected points of one label are a segment.
//   4. Each segment (its points' Voronoi cells, clipped near the points) is recognised again as a region for its
//      final normal and plane probability; small segments and those the recognition rejects are dropped. A
//      vertical plane is split where its colour changes or its edges turn along the image's columns (one facade
//      meeting the next, or a wall round a corner: FacadeColumnCuts, column_cuts.h), and each part recognised
//      again.
// Pixels are the working image's (the model's working width); normals are unit, camera frame, towards the camera.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pdvo/annotations/annotation.h"
#include "pdvo/common/camera.h"
#include "pdvo/infer/recogniser.h"

namespace pdvo {

struct DetectorOptions {
  int cell = 8;                                       // px: windows start and end on this grid
  std::vector<double> window_sizes = {64, 112, 176};  // px: each window shape's geometric-mean side
  std::vector<double> window_aspects = {1, 2, 0.5};   // width / height of the window shapes
  double overlap = 0.5;              // share of a window's side that the next window of its shape overlaps
  bool fuse_window_normals = false;  // fuse each window's normal with its edges' vanishing direction (slower)
  double normal_scale_deg = 15;      // the Cauchy scale of a point's robust mean normal
  // A point's planarity's log-odds move by this times its two words' plane log-odds (the model's, learned in
  // training; their sum at most 3 either way): leaves, cars and sky have words of their own. 0: off.
  double word_prior_weight = 1;
  // The graph's edges: weight = exp(-(distance / distance_scale)^2 / 2) exp(-(colour difference / colour_scale)^2
  // / 2), colours in [0, 1] per channel.
  double distance_scale = 25;  // px
  double colour_scale = 0.15;
  double plane_smoothness = 1.5;          // MRF 1's Potts weight on a full-weight edge
  double orientation_bandwidth_deg = 12;  // mean shift on the planar points' normals
  double orientation_merge_deg = 15;      // modes nearer than this are one orientation
  int max_orientations = 6;
  double orientation_scale_deg = 20;    // MRF 2's data cost: (angle / scale)^2, at most 4
  double orientation_smoothness = 1.5;  // MRF 2's Potts weight on a full-weight edge
  int min_segment_points = 10;          // smaller segments are dropped
  // A vertical plane segment is split into runs of columns where its colour changes or its horizontal edges turn
  // (FacadeColumnCuts, column_cuts.h; the price of a run in each, 0: that cue off), and the parts recognised again.
  double column_split_penalty = 3000;  // colour: squared CIELAB units summed over columns
  double azimuth_split_penalty = 80;   // turn: robust losses of edges of mean strength
  int column_split_width = 12;         // px: the narrowest part
  double column_join_colour = 6;       // CIELAB units: a part between two of this colour, no wider than either, joins
                                       // them (a facade's windows or door; column_cuts.h); 0: never
  double min_plane_probability = 0.5;  // a plane segment recognised again below this is dropped
  double cell_radius = 16;             // px: a segment's area is its points' Voronoi cells within this distance
  // The image is described with salient points of its own, in place of the model's (FeatureOptions' quality and
  // min_distance; the shipped model's are 0.01 and 4 px): weaker corners, farther apart, cover the smooth parts
  // of planes that the model's points leave empty, with fewer points in all (docs/detector.md).
  double point_quality = 0.001;
  double point_min_distance = 8;  // px
  // The stages, for measuring what each adds. Off: a point is planar if its planarity exceeds 0.5 (MRF 1); takes
  // its nearest orientation (MRF 2); a segment's normal is its points' robust mean and its score their mean
  // planarity, and it is kept (re-recognition).
  bool mrf_planes = true;
  bool mrf_orientations = true;
  bool rerecognise = true;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("cell", self.cell);
    visit("window_sizes", self.window_sizes);
    visit("window_aspects", self.window_aspects);
    visit("overlap", self.overlap);
    visit("fuse_window_normals", self.fuse_window_normals);
    visit("normal_scale_deg", self.normal_scale_deg);
    visit("word_prior_weight", self.word_prior_weight);
    visit("distance_scale", self.distance_scale);
    visit("colour_scale", self.colour_scale);
    visit("plane_smoothness", self.plane_smoothness);
    visit("orientation_bandwidth_deg", self.orientation_bandwidth_deg);
    visit("orientation_merge_deg", self.orientation_merge_deg);
    visit("max_orientations", self.max_orientations);
    visit("orientation_scale_deg", self.orientation_scale_deg);
    visit("orientation_smoothness", self.orientation_smoothness);
    visit("min_segment_points", self.min_segment_points);
    visit("column_split_penalty", self.column_split_penalty);
    visit("azimuth_split_penalty", self.azimuth_split_penalty);
    visit("column_split_width", self.column_split_width);
    visit("column_join_colour", self.column_join_colour);
    visit("min_plane_probability", self.min_plane_probability);
    visit("cell_radius", self.cell_radius);
    visit("point_quality", self.point_quality);
    visit("point_min_distance", self.point_min_distance);
    visit("mrf_planes", self.mrf_planes);
    visit("mrf_orientations", self.mrf_orientations);
    visit("rerecognise", self.rerecognise);
  }
  bool Check() const;
  bool operator==(const DetectorOptions&) const = default;
};

struct DetectedWindow {
  cv::Rect box;
  double plane_probability = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// Per point, from the windows that hold it (Region::Contains): its planarity, the median of their plane
// probabilities (0.5 if none), and its normal, their normals' robust mean weighted by their probabilities (Cauchy
// scale `normal_scale_deg`; zero if none).
struct PointPooling {
  std::vector<double> planarity;
  std::vector<Eigen::Vector3d> normals;
};
PointPooling PoolWindows(const std::vector<cv::Point2f>& points, const std::vector<DetectedWindow>& windows,
                         double normal_scale_deg);

struct DetectedSegment {
  bool planar = false;
  std::vector<int> points;                           // indices into Detections::points
  cv::Mat mask;                                      // CV_8U, working size: the segment's area
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // planes: from the segment's recognition
  double score = 0;  // planes: its plane probability; non-planes: 1 - the points' mean planarity
};

struct Detections {
  cv::Size image_size;                    // working size
  double scale = 1;                       // working width / the image's width
  std::vector<cv::Point2f> points;        // salient points, working pixels
  std::vector<double> planarity;          // per point, in [0, 1]; 0.5 where no window held it
  std::vector<Eigen::Vector3d> normals;   // per point; zero where no window held it
  std::vector<int> plane_label;           // per point: MRF 1 (1 plane, 0 not)
  std::vector<int> orientation;           // per point: MRF 2's orientation, -1 for non-planar points
  std::vector<DetectedWindow> windows;    // the windows recognised (with enough points)
  std::vector<DetectedSegment> segments;  // planes, then non-planes
  struct Times {
    double describe = 0, windows = 0, pooling = 0, segmentation = 0, segments = 0, total = 0;  // ms
  } times;

  // As an annotation of the original image (`image_path` relative to the JSON's folder, `width` x `height` its
  // size): the plane segments as `plane` shapes with their normal and score, the non-planes as `non-plane`.
  Annotation ToAnnotation(const std::string& image_path, int width, int height,
                          const std::optional<Camera>& camera = std::nullopt) const;
  // The planes as the odometry takes them, in pixels of the original image (`width` x `height`): the polygons of
  // ToAnnotation, each with the planar salient points inside it.
  std::vector<DetectedPlane> Planes(int width, int height) const;
};

class Detector {
 public:
  // Throws InvalidArgument for invalid options.
  Detector(PlaneModel model, const DetectorOptions& options);
  const Recogniser& recogniser() const { return recogniser_; }
  const DetectorOptions& options() const { return options_; }

  // Planes in an 8-bit BGR or grey image of any size (resized to the model's working width); `camera` is the
  // image's (undistorted, of the image's size) if known. Throws InvalidArgument for an empty image, one smaller
  // than the smallest window, or a camera of another size. Const and thread-safe: one detector may serve several
  // threads.
  Detections Detect(const cv::Mat& image, const std::optional<Camera>& camera = std::nullopt) const;

 private:
  Recogniser recogniser_;
  DetectorOptions options_;
};

}  // namespace pdvo
