#include "pdvo/infer/recogniser.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/infer/spatiogram.h"
#include "pdvo/infer/topics.h"

namespace pdvo {

ImageWords QuantiseFeatures(const Features& f, const Vocabulary& gradient_words, const Vocabulary& colour_words) {
  ImageWords w;
  w.points = f.points;
  w.gradient = gradient_words.Quantise(f.gradient);
  w.colour = colour_words.Quantise(f.colour);
  w.angle = f.orientation;
  w.coherence = f.coherence;
  w.image_size = f.image_size;
  return w;
}

cv::Mat ToWorkingSize(const cv::Mat& image, int working_width, double* scale) {
  PDVO_THROW_CHECK(!image.empty(), InvalidArgument, "empty image");
  if (working_width <= 0 || image.cols == working_width) {
    if (scale) *scale = 1;
    return image;
  }
  const double s = static_cast<double>(working_width) / image.cols;
  cv::Mat out;
  cv::resize(image, out, cv::Size(working_width, std::max(1, static_cast<int>(std::lround(image.rows * s)))), 0, 0,
             s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
  if (scale) *scale = s;
  return out;
}

RegionWords CollectRegionWords(const ImageWords& words, const Region& region, int gradient_words, int colour_words) {
  RegionWords r;
  r.box = cv::Rect2d(region.box.x - 0.5, region.box.y - 0.5, region.box.width, region.box.height);
  r.image_size = words.image_size;
  r.histogram = Eigen::VectorXd::Zero(gradient_words + colour_words);
  for (size_t i = 0; i < words.size(); ++i) {
    if (!region.Contains(words.points[i])) continue;
    const int g = words.gradient[i], c = words.colour[i];
    PDVO_THROW_CHECK(g >= 0 && g < gradient_words && c >= 0 && c < colour_words, InvalidArgument,
                     "region words: a word out of the vocabulary's range");
    r.points.push_back(words.points[i]);
    r.gradient.push_back(g);
    r.colour.push_back(gradient_words + c);
    r.orientation.push_back(
        std::min(kOrientationBins - 1, static_cast<int>(words.angle[i] / CV_PI * kOrientationBins)));
    r.angle.push_back(words.angle[i]);
    r.coherence.push_back(words.coherence[i]);
    r.histogram[g] += 1;
    r.histogram[gradient_words + c] += 1;
  }
  if (r.size() > 0) r.histogram /= 2.0 * r.size();
  return r;
}

Eigen::VectorXd LayoutFeature(const RegionWords& r) {
  PDVO_THROW_CHECK(r.image_size.width > 0 && r.image_size.height > 0, InvalidArgument, "layout: no image size");
  const double w = r.image_size.width;
  const Eigen::Vector2d image_centre(r.image_size.width / 2.0, r.image_size.height / 2.0);
  const Eigen::Vector2d centre(r.box.x + r.box.width / 2, r.box.y + r.box.height / 2);
  // Per family, weighted least squares of the edge angle on (1, dx, dy), dx and dy from the region's centre in
  // image widths; a small ridge keeps the slopes of a thin or tiny region finite.
  constexpr double kRidge = 1e-4;
  std::array<Eigen::Matrix3d, 2> normal_matrix = {kRidge * Eigen::Matrix3d::Identity(),
                                                  kRidge * Eigen::Matrix3d::Identity()};
  normal_matrix[0](0, 0) = normal_matrix[1](0, 0) = 0;
  std::array<Eigen::Vector3d, 2> moment = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<double, 2> mass = {0, 0};
  for (int i = 0; i < r.size(); ++i) {
    // The edge runs across the gradient: its angle, folded into (-pi/4, pi/4] about its family's axis.
    const double gradient = r.angle[i];
    const int family = gradient > CV_PI / 4 && gradient <= 3 * CV_PI / 4 ? 0 : 1;  // 0: near horizontal edges
    double edge = family == 0 ? gradient - CV_PI / 2 : gradient;
    if (edge > CV_PI / 2) edge -= CV_PI;
    const Eigen::Vector3d a(1, (r.points[i].x - centre.x()) / w, (r.points[i].y - centre.y()) / w);
    const double weight = static_cast<double>(r.coherence[i]) * r.coherence[i];
    normal_matrix[family] += weight * a * a.transpose();
    moment[family] += weight * edge * a;
    mass[family] += weight;
  }
  Eigen::VectorXd out(kLayoutDims);
  out.head<4>() << (centre - image_centre) / w, r.box.width / w, r.box.height / w;
  for (int f = 0; f < 2; ++f) {
    out.segment<3>(4 + 3 * f) =
        mass[f] > 0 ? Eigen::Vector3d(normal_matrix[f].ldlt().solve(moment[f])) : Eigen::Vector3d::Zero();
  }
  out[10] = mass[0] + mass[1] > 0 ? mass[0] / (mass[0] + mass[1]) : 0.5;
  out.tail<2>() = r.edge_structure;
  return out;
}

Eigen::VectorXd RegionFeature(const RegionWords& region, const Eigen::MatrixXd& topics, int topic_iterations) {
  // Topics: every point contributes its gradient word and its colour word.
  std::vector<int> ids = region.gradient;
  ids.insert(ids.end(), region.colour.begin(), region.colour.end());
  std::vector<cv::Point2f> positions = region.points;
  positions.insert(positions.end(), region.points.begin(), region.points.end());
  const Eigen::VectorXd weights = ProjectOntoTopics(topics, region.histogram, topic_iterations);
  const Eigen::VectorXd by_topic = ComputeSpatiogram(topics, ids, positions, region.box, weights).ToVector();
  // Orientation bins as the words of an identity basis; their weights are the bins' shares of the points.
  Eigen::VectorXd shares = Eigen::VectorXd::Zero(kOrientationBins);
  for (int b : region.orientation) shares[b] += 1.0 / region.size();
  const Eigen::VectorXd by_orientation =
      ComputeSpatiogram(Eigen::MatrixXd::Identity(kOrientationBins, kOrientationBins), region.orientation,
                        region.points, region.box, shares)
          .ToVector();
  const Eigen::VectorXd layout = LayoutFeature(region);
  Eigen::VectorXd feature(by_topic.size() + by_orientation.size() + layout.size());
  feature << by_topic, by_orientation, layout;
  return feature;
}

AnnotatedImage ReadAnnotatedImage(const std::string& annotation_path, int working_width) {
  AnnotatedImage a;
  a.annotation_path = annotation_path;
  a.annotation = ReadAnnotation(annotation_path);
  ValidateOrThrow(a.annotation, annotation_path);
  const std::string image_path = ResolveImagePath(a.annotation, annotation_path);
  const cv::Mat image = ReadImage(image_path, cv::IMREAD_COLOR);
  PDVO_THROW_CHECK(image.cols == a.annotation.image_width && image.rows == a.annotation.image_height, FormatError,
                   image_path << ": image is " << image.cols << "x" << image.rows << ", its annotation says "
                              << a.annotation.image_width << "x" << a.annotation.image_height);
  a.image = ToWorkingSize(image, working_width);
  if (a.annotation.camera) a.camera = a.annotation.camera->Rescaled(a.image.cols, a.image.rows);
  return a;
}

Recogniser::Recogniser(PlaneModel model) : model_(std::move(model)) {
  PDVO_THROW_CHECK(model_.topics.rows() == model_.gradient_words.size() + model_.colour_words.size(), InvalidArgument,
                   "recogniser: the topic basis does not match the vocabularies");
  const Eigen::Index dims = RegionFeatureDims(static_cast<int>(model_.topics.cols()));
  PDVO_THROW_CHECK(!model_.classifiers.empty(), InvalidArgument, "recogniser: the model has no classifier");
  const bool classifiers_fit = std::all_of(model_.classifiers.begin(), model_.classifiers.end(), [&](const Learned& f) {
    return f.kind == LearnerKind::kRvm ? f.rvm.size() == 0 || f.rvm.vectors.cols() == dims
                                       : f.ml && f.ml->getVarCount() == dims;
  });
  PDVO_THROW_CHECK(model_.feature_mean.size() == dims && classifiers_fit, InvalidArgument,
                   "recogniser: the model's features are " << model_.feature_mean.size() << "-D, expected " << dims);
  if (model_.learner() == LearnerKind::kRvm) {
    std::vector<const RvmFunction*> functions;
    for (const Learned& f : model_.classifiers) functions.push_back(&f.rvm);
    for (const Learned& f : model_.normal) functions.push_back(&f.rvm);
    rvms_ = RvmBank(functions);
  }
}

ImageWords Recogniser::Describe(const cv::Mat& image, const std::optional<Camera>& camera,
                                const FeatureOptions* points) const {
  const RecogniserOptions& o = model_.options;
  ImageWords words = QuantiseFeatures(ExtractFeatures(image, points ? *points : o.features), model_.gradient_words,
                                      model_.colour_words);
  words.edges = FindEdgePlanes(image, camera, o.vanishing);
  return words;
}

RegionPrediction Recogniser::Predict(const Eigen::VectorXd& feature) const {
  return PredictRows(feature.transpose()).front();
}

std::vector<RegionPrediction> Recogniser::PredictRows(const Eigen::MatrixXd& features) const {
  PDVO_THROW_CHECK(features.cols() == model_.feature_mean.size() || features.rows() == 0, InvalidArgument,
                   "recogniser: " << features.cols() << "-D features for a model of " << model_.feature_mean.size());
  const Eigen::MatrixXd x = (features.rowwise() - model_.feature_mean.transpose()).array().rowwise() /
                            model_.feature_scale.transpose().array();
  const Eigen::Index classifiers = static_cast<Eigen::Index>(model_.classifiers.size());
  Eigen::VectorXd probability = Eigen::VectorXd::Zero(x.rows());
  Eigen::MatrixXd normal(x.rows(), 3);
  if (model_.learner() == LearnerKind::kRvm) {  // classifiers' logits, then the normal's components
    const Eigen::MatrixXd values = rvms_.Evaluate(x);
    probability = (1.0 + (-values.leftCols(classifiers)).array().exp()).inverse().matrix().rowwise().sum();
    normal = values.rightCols(3);
  } else {
    for (const Learned& f : model_.classifiers) probability += f.Evaluate(x);
    for (int c = 0; c < 3; ++c) normal.col(c) = model_.normal[c].Evaluate(x);
  }
  probability /= static_cast<double>(classifiers);
  std::vector<RegionPrediction> out(static_cast<size_t>(x.rows()));
  for (Eigen::Index k = 0; k < x.rows(); ++k) {
    RegionPrediction& p = out[static_cast<size_t>(k)];
    p.valid = true;
    p.plane_probability = probability[k];
    const Eigen::Vector3d n = normal.row(k).transpose();
    if (n.norm() > 1e-9) p.normal = n.normalized();
  }
  return out;
}

RegionPrediction Recogniser::Recognise(const ImageWords& words, const Region& region) const {
  const RecogniserOptions& o = model_.options;
  RegionWords r = CollectRegionWords(words, region, model_.gradient_words.size(), model_.colour_words.size());
  RegionPrediction p;
  if (r.size() >= o.min_points) {
    r.edge_structure = EdgeStructure(words.edges, region, o.vanishing);
    p = Predict(RegionFeature(r, model_.topics, o.topic_iterations));
    p.normal = FuseNormal(p.normal, words.edges, region, o.vanishing);
  }
  p.points = r.size();
  return p;
}

}  // namespace pdvo
