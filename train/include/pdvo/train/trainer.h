// Training the plane recogniser (the paper's section III): regions sampled from annotations -> salient points
// and descriptors -> two vocabularies (k-means) -> word histograms -> topics (orthogonal NMF) -> spatiograms ->
// a committee of RVM classifiers and three RVM normal regressors (dlib, Tipping & Faul; or OpenCV ml's SVM, kNN
// or random trees), kernel widths (settings) chosen by cross-validation grouped by image -> one PlaneModel.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pdvo/annotations/regions.h"
#include "pdvo/infer/model.h"
#include "pdvo/train/onmf.h"

namespace pdvo {

struct RvmOptions {
  // RBF kernel widths tried, gamma = value / feature dimensions (features are standardised).
  std::vector<double> gammas = {0.2, 0.5};
  double epsilon = 1e-3;     // dlib's stopping tolerance (classifier)
  int max_iterations = 400;  // classifier iterations; normal regressors: steps (bounds their relevance vectors)

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("gammas", self.gammas);
    visit("epsilon", self.epsilon);
    visit("max_iterations", self.max_iterations);
  }
  bool Check() const;
  bool operator==(const RvmOptions&) const = default;
};

// OpenCV ml's learners, their settings tried by the same grouped cross-validation as the RVM's kernel width.
struct SvmOptions {
  std::vector<double> gammas = {0.2, 0.5};  // RBF widths, gamma = value / feature dimensions
  std::vector<double> c = {1, 10};          // the soft margin's cost; every (gamma, C) is tried
  double epsilon = 0.1;                     // the normal regressors' insensitive zone (EPS_SVR)

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("gammas", self.gammas);
    visit("c", self.c);
    visit("epsilon", self.epsilon);
  }
  bool Check() const;
  bool operator==(const SvmOptions&) const = default;
};

struct KnnOptions {
  std::vector<double> k = {5, 15};  // neighbours (whole numbers), each tried

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("k", self.k);
  }
  bool Check() const;
  bool operator==(const KnnOptions&) const = default;
};

struct TreesOptions {
  int trees = 100;
  std::vector<double> max_depth = {8, 16};  // each tried
  int min_samples = 2;                      // a node with fewer is not split

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("trees", self.trees);
    visit("max_depth", self.max_depth);
    visit("min_samples", self.min_samples);
  }
  bool Check() const;
  bool operator==(const TreesOptions&) const = default;
};

struct TrainOptions {
  RecogniserOptions recogniser;
  RegionSamplingOptions regions;
  int gradient_words = 300;
  int colour_words = 60;
  int vocabulary_samples = 40000;  // descriptors drawn (per vocabulary) for k-means
  int kmeans_iterations = 20;
  OnmfOptions topics;
  // Training cost grows with the cube of the sample count: regions are drawn at random up to these bounds.
  int max_regions_per_class = 600;  // classes are balanced to the smaller class, at most this many each
  int max_normal_regions = 400;     // planes with normals for the regressors
  // The plane probability is the mean of this many RVM classifiers (a committee), each trained on its own draw of
  // balanced regions from all there are (bagging): one draw's classifier has few relevance vectors and moves
  // with the draw. Their kernel width is chosen by cross-validation on the first draw.
  int classifiers = 15;  // the committee's size
  // The layout values (see LayoutFeature) count this much more than the others in the kernel's distance: a few
  // values among ~170 would otherwise hardly move it.
  double layout_weight = 6;
  // The classifiers' and the normal regressors' learner (the committee and all after it as for the RVM).
  LearnerKind classifier = LearnerKind::kRvm;
  RvmOptions rvm;
  SvmOptions svm;
  KnnOptions knn;
  TreesOptions trees;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("recogniser", self.recogniser);
    visit("regions", self.regions);
    visit("gradient_words", self.gradient_words);
    visit("colour_words", self.colour_words);
    visit("vocabulary_samples", self.vocabulary_samples);
    visit("kmeans_iterations", self.kmeans_iterations);
    visit("topics", self.topics);
    visit("max_regions_per_class", self.max_regions_per_class);
    visit("max_normal_regions", self.max_normal_regions);
    visit("classifiers", self.classifiers);
    visit("layout_weight", self.layout_weight);
    visit("classifier", self.classifier);
    visit("rvm", self.rvm);
    visit("svm", self.svm);
    visit("knn", self.knn);
    visit("trees", self.trees);
  }
  bool Check() const;
  bool operator==(const TrainOptions&) const = default;
};

// Each word's plane log-odds (PlaneModel::word_plane_log_odds), counted over the annotation files' salient points
// with `model`'s feature options and vocabularies, as TrainModel counts them over its training files: the detector's
// words' prior for a model trained before version 6, without training it again (pdvo train --word-prior-of).
Eigen::VectorXd CountWordPlaneLogOdds(const PlaneModel& model, const std::vector<std::string>& annotation_files);

// Trains on the annotation files (LabelMe JSON with images beside them). `folds` >= 2 cross-validates the
// kernel widths (folds grouped by image); 1 takes the first width of each list. Throws pdvo::Error for no
// files, a missing image, or a class without examples. The same files, options and seed give the same model.
PlaneModel TrainModel(const std::vector<std::string>& annotation_files, const TrainOptions& options, uint64_t seed,
                      int folds, const std::string& data_description);

}  // namespace pdvo
