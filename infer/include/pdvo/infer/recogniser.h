// Recognising a region (the paper's section III): its salient points' visual words -> a topic histogram ->
// a spatiogram -> RVMs -> plane probability and normal. An image is described once (points and words) and any
// number of regions of it are then recognised from that description.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "pdvo/annotations/regions.h"
#include "pdvo/infer/model.h"

namespace pdvo {

// Line orientations are quantised into this many bins over [0, pi).
inline constexpr int kOrientationBins = 8;

// An image's salient points and each point's gradient word, colour word and dominant gradient direction.
struct ImageWords {
  std::vector<cv::Point2f> points;
  std::vector<int> gradient;
  std::vector<int> colour;
  std::vector<float> angle;      // radians in [0, pi), see Features::orientation
  std::vector<float> coherence;  // in [0, 1]
  cv::Size image_size;
  EdgePlanes edges;  // straight edges (see vanishing.h)
  size_t size() const { return points.size(); }
};

ImageWords QuantiseFeatures(const Features& features, const Vocabulary& gradient_words, const Vocabulary& colour_words);

// `image` resized to `working_width` (unchanged if 0 or already that wide); `scale` gets new / old width.
cv::Mat ToWorkingSize(const cv::Mat& image, int working_width, double* scale = nullptr);

// The points of a region with their words (colour words offset past the gradient words), orientation bins and
// gradient directions, and the normalised histogram of all their words.
struct RegionWords {
  std::vector<cv::Point2f> points;
  std::vector<int> gradient;     // per point, in [0, gradient words)
  std::vector<int> colour;       // per point, in [gradient words, gradient + colour words)
  std::vector<int> orientation;  // per point, in [0, kOrientationBins)
  std::vector<float> angle;      // per point, as in ImageWords
  std::vector<float> coherence;
  cv::Rect2d box;  // the region's extent in pixel-edge coordinates
  cv::Size image_size;
  Eigen::VectorXd histogram;  // gradient words + colour words, sums to 1 (zero if no points)
  Eigen::Vector2d edge_structure = Eigen::Vector2d::Zero();  // see EdgeStructure; filled by the caller
  int size() const { return static_cast<int>(points.size()); }
};
RegionWords CollectRegionWords(const ImageWords& words, const Region& region, int gradient_words, int colour_words);

// The region's layout: where it lies in the image and how its edges' directions vary across it, the
// perspective cue to a plane's orientation (edges of one 3D direction converge towards their vanishing point).
// Each point's edge (across its gradient direction) joins one of two families, near horizontal or near
// vertical, and gets its angle from its family's axis in (-pi/4, pi/4]. Per family, a weighted (coherence
// squared) least-squares plane angle = a + b dx + c dy over the points, dx, dy from the region's centre.
// Lengths are in image widths. Values: the centre from the image centre (2), width and height (2), (a, b, c)
// of the near-horizontal edges and of the near-vertical ones (3 + 3, zero without such edges), and the near-
// horizontal family's share of the weight (1), and the region's edge structure (2, see EdgeStructure).
inline constexpr int kLayoutDims = 13;
Eigen::VectorXd LayoutFeature(const RegionWords& region);

// The feature vector of a region (not standardised): the spatiogram of its topics (6 values per topic), then
// the spatiogram of its points' dominant gradient orientations (6 values per orientation bin): where in the
// region each edge direction lies, the perspective cue to the orientation of a textured plane; then its layout.
// `topics` has the gradient words' rows first, then the colour words'.
Eigen::VectorXd RegionFeature(const RegionWords& region, const Eigen::MatrixXd& topics, int topic_iterations);
// Its size for `topics` topics.
inline int RegionFeatureDims(int topics) { return 6 * (topics + kOrientationBins) + kLayoutDims; }

// An annotation and its image at a working width (the annotation itself stays at full resolution).
struct AnnotatedImage {
  std::string annotation_path;
  Annotation annotation;
  cv::Mat image;                 // 8-bit BGR, working size
  std::optional<Camera> camera;  // at the working size, when the annotation gives one
};
// Reads, validates and resizes; throws pdvo::Error naming the file at fault (JSON or image).
AnnotatedImage ReadAnnotatedImage(const std::string& annotation_path, int working_width);

struct RegionPrediction {
  bool valid = false;  // false: too few salient points to say
  int points = 0;
  double plane_probability = 0;
  // Unit, camera frame, towards the camera: n . ray <= 0 for the ray through the region's centre (Recognise).
  Eigen::Vector3d normal = Eigen::Vector3d(0, 0, -1);
};

class Recogniser {
 public:
  explicit Recogniser(PlaneModel model);
  const PlaneModel& model() const { return model_; }

  // Points, words and edges of an image already at the working size (see ToWorkingSize). Without `camera`,
  // Camera::WithFieldOfView with the options' field of view (see VanishingOptions). The salient points are the
  // model's (its options' features) unless `points` gives others.
  ImageWords Describe(const cv::Mat& image, const std::optional<Camera>& camera = std::nullopt,
                      const FeatureOptions* points = nullptr) const;
  RegionPrediction Recognise(const ImageWords& words, const Region& region) const;
  // The same from a region's (not standardised) feature vector, without the fusion with the region's edges
  // (FuseNormal in vanishing.h) and without turning the normal to face the camera, which need the image. The
  // plane probability is the mean of the classifiers' logistic probabilities.
  RegionPrediction Predict(const Eigen::VectorXd& feature) const;
  // Predict for each row of `features` (one region's feature per row), with the RVMs evaluated together (RvmBank).
  std::vector<RegionPrediction> PredictRows(const Eigen::MatrixXd& features) const;

 private:
  PlaneModel model_;
  RvmBank rvms_;  // the classifiers', then the three normal regressors', when the learner is the RVM
};

}  // namespace pdvo
