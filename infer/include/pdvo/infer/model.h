// The plane recogniser's model: everything inference needs, in ONE versioned file (cv::FileStorage YAML):
// the recogniser options (version 2 added their `vanishing` section and two layout values), the two
// vocabularies, the topic basis, the feature standardisation, a committee of classifiers (plane probability;
// version 3, one classifier before) and three regressors (normal components), and a training card. Version 4
// names the learner (`learner`: RVM, or OpenCV ml's SVM, kNN or random trees); version 3 files (RVM) are read.
// Version 6 adds each word's plane log-odds (the detector's prior on a point's planarity from its words; a model
// without them, such as one of version 5, gives the detector no prior).
// Writing is atomic; re-writing a read model gives the same bytes. Relevance vectors are stored in single
// precision (most of the file's bytes; predictions move by about 1e-7 relative), everything else in double.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/ml.hpp>
#include <string>
#include <vector>

#include "pdvo/infer/vanishing.h"
#include "pdvo/vocab/features.h"
#include "pdvo/vocab/vocabulary.h"

namespace pdvo {

inline constexpr const char* kModelFormat = "pdvo-plane-model";
inline constexpr int kModelVersion = 6;  // 5: ends with a checksum line (see SealModelText); 6: word log-odds

// A sparse kernel machine as dlib's RVM trainers produce it: f(x) = sum_i w_i exp(-gamma |x - v_i|^2) - bias.
struct RvmFunction {
  double gamma = 1;
  double bias = 0;
  Eigen::VectorXd weights;  // one per relevance vector
  Eigen::MatrixXd vectors;  // relevance vectors, one per row

  double operator()(const Eigen::VectorXd& x) const;
  // The same for each row of `rows` at once (a bank of one, RvmBank below: equal to about 1e-6 relative).
  Eigen::VectorXd Evaluate(const Eigen::MatrixXd& rows) const;
  int size() const { return static_cast<int>(weights.size()); }
};

// Several RVMs evaluated together. The functions of one model share most of their relevance vectors (the default
// model: 1,315 vectors, 798 distinct per kernel width), so each row is compared with each distinct vector once
// (one matrix product per kernel width, in single precision, as the vectors are stored) and each function sums
// its own. Equal to the functions' Evaluate to about 1e-6 relative.
class RvmBank {
 public:
  RvmBank() = default;
  explicit RvmBank(const std::vector<const RvmFunction*>& functions);
  // rows x functions: each function's value at each row.
  Eigen::MatrixXd Evaluate(const Eigen::MatrixXd& rows) const;
  int functions() const { return functions_; }

 private:
  struct Group {  // the functions of one kernel width
    double gamma = 1;
    Eigen::MatrixXf vectors;  // distinct relevance vectors, one per row
    Eigen::VectorXd norms;    // their squared norms
    Eigen::MatrixXd weights;  // distinct vectors x functions of the bank (zero where a function lacks the vector)
  };
  std::vector<Group> groups_;
  Eigen::RowVectorXd bias_;
  int functions_ = 0;
};

// The kinds of learner for the classifiers and the normal regressors (pdvo train --classifier).
enum class LearnerKind { kRvm, kSvm, kKnn, kTrees };
constexpr std::array<std::pair<LearnerKind, const char*>, 4> OptionNames(LearnerKind) {
  return {{{LearnerKind::kRvm, "rvm"},
           {LearnerKind::kSvm, "svm"},
           {LearnerKind::kKnn, "knn"},
           {LearnerKind::kTrees, "trees"}}};
}

// One learned function of the standardised region feature: a classifier's plane probability or a regressor's
// value. RVM: the kernel expansion above (a classifier's value is a logit). The others are OpenCV ml models, all
// with the feature in single precision: SVM (RBF kernel; a classifier's decision value becomes a probability by
// Platt's sigmoid, fitted on its training rows), kNN (a classifier: the share of planes among the k nearest,
// (planes + 1) / (k + 2); a regressor: their mean), random trees (a classifier: the share of trees that vote
// plane; a regressor: the trees' mean). Const evaluation is thread-safe.
struct Learned {
  LearnerKind kind = LearnerKind::kRvm;
  bool classifier = true;
  RvmFunction rvm;                   // kRvm
  cv::Ptr<cv::ml::StatModel> ml;     // the others
  double platt_a = -1, platt_b = 0;  // SVM classifier: p = 1 / (1 + exp(platt_a f + platt_b))
  int size = 0;                      // relevance or support vectors, stored samples (kNN), tree nodes

  static Learned Rvm(RvmFunction f, bool classifier);
  // Probabilities (classifier) or values (regressor), one per row; for one row (an RVM's as RvmFunction's
  // operator(), Evaluate's equal to rounding).
  Eigen::VectorXd Evaluate(const Eigen::MatrixXd& rows) const;
  double operator()(const Eigen::VectorXd& x) const;
};

struct RecogniserOptions {
  int working_width = 320;  // images are resized to this width before description (0: as given)
  FeatureOptions features;
  int min_points = 8;          // regions with fewer salient points are not recognised
  int topic_iterations = 100;  // non-negative projection onto the topics
  VanishingOptions vanishing;  // the edges' vanishing direction, fused with the regressors' normals

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("working_width", self.working_width);
    visit("features", self.features);
    visit("min_points", self.min_points);
    visit("topic_iterations", self.topic_iterations);
    visit("vanishing", self.vanishing);
  }
  bool Check() const;
  bool operator==(const RecogniserOptions&) const = default;
};

// What the model was trained on and how well it did in cross-validation (filled by training).
struct ModelCard {
  std::string data;  // the annotation folders, as given
  int images = 0;
  int plane_regions = 0;  // used for each classifier (after balancing)
  int non_plane_regions = 0;
  int normal_regions = 0;      // used for the normal regressors
  int folds = 0;               // cross-validation folds (grouped by image)
  double cv_accuracy = 0;      // one classifier (the first draw), at the chosen kernel width
  double cv_normal_error = 0;  // mean angle, degrees
  int seed = 0;
  // What trained it: the training options ("key=value" as --set takes them, space-separated), and the pdvo
  // version and git commit of the build (empty in models trained before they were recorded).
  std::string training_options;
  std::string pdvo_version;
  std::string git_commit;
  // How the word log-odds were counted, when not by this training (pdvo train --word-prior-of): the annotation
  // folders and the pdvo version and commit that counted them; empty otherwise.
  std::string word_prior;
};

struct PlaneModel {
  RecogniserOptions options;
  Vocabulary gradient_words;
  Vocabulary colour_words;
  Eigen::MatrixXd topics;  // (gradient words + colour words) x topics, non-negative
  // Per word (gradient words, then colour words): log(P(plane | word) / P(non-plane | word)) over the training
  // images' annotated salient points, less the log-odds of all of them (0: the word says nothing); each word's
  // counts smoothed towards the overall share by kWordPriorCounts points. Empty in models trained before version 6.
  Eigen::VectorXd word_plane_log_odds;
  Eigen::VectorXd feature_mean;  // standardisation of the region features
  Eigen::VectorXd feature_scale;
  // The plane probability is the mean of the members' (see Recogniser::Predict). Members are trained on
  // different draws of the training regions (bagging). All classifiers and regressors are of one kind.
  std::vector<Learned> classifiers;
  std::array<Learned, 3> normal;  // x, y, z of the normal before normalisation
  LearnerKind learner() const { return classifiers.empty() ? LearnerKind::kRvm : classifiers.front().kind; }
  ModelCard card;

  std::string ToYaml() const;  // sealed (SealModelText)
  // Throws FormatError naming `where` for another format, another version, a truncated or malformed file, or one
  // whose checksum does not match its content. Versions 3 and 4 (no checksum) are read with a warning.
  static PlaneModel FromYaml(const std::string& text, const std::string& where);
  void Write(const std::string& path) const;  // atomically
  static PlaneModel Read(const std::string& path);
};

// A model file's last line is "# crc32: XXXXXXXX", the CRC-32 (zlib's) of every byte before it, so that a flipped
// bit or an edit is found on reading. SealModelText returns `text` with that line replaced or added: for tools
// and tests that edit a model on purpose.
std::string SealModelText(std::string text);

inline constexpr double kWordPriorCounts = 20;
// PlaneModel::word_plane_log_odds from each word's salient points on annotated planes and non-planes (vectors of
// gradient words + colour words counts).
Eigen::VectorXd WordPlaneLogOdds(const Eigen::VectorXd& plane_counts, const Eigen::VectorXd& non_plane_counts);

}  // namespace pdvo
