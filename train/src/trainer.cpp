#include "pdvo/train/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"
#include "pdvo/eval/recognition.h"
#include "pdvo/infer/recogniser.h"
#include "pdvo/train/learners.h"

namespace pdvo {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

struct SampledRegion {
  int image = 0;
  LabelledRegion labelled;
  RegionWords words;
  Eigen::Vector2d edge_structure;  // found when its image is described (the image's edges are not kept)
};

// Up to `count` descriptors (gradient or colour) drawn at random from all images, in image order.
cv::Mat DrawDescriptors(const std::vector<Features>& features, bool gradient, int count, std::mt19937_64& rng) {
  std::vector<std::pair<int, int>> all;
  for (size_t i = 0; i < features.size(); ++i) {
    for (size_t r = 0; r < features[i].size(); ++r) all.emplace_back(static_cast<int>(i), static_cast<int>(r));
  }
  std::shuffle(all.begin(), all.end(), rng);
  if (static_cast<int>(all.size()) > count) all.resize(count);
  std::sort(all.begin(), all.end());
  cv::Mat out(static_cast<int>(all.size()), gradient ? kGradientDims : kColourDims, CV_32F);
  for (size_t k = 0; k < all.size(); ++k) {
    const Features& f = features[all[k].first];
    (gradient ? f.gradient : f.colour).row(all[k].second).copyTo(out.row(static_cast<int>(k)));
  }
  return out;
}

// Cross-validation folds grouped by image: the images are shuffled and dealt round the folds.
std::vector<int> FoldOfImage(int images, int folds, std::mt19937_64& rng) {
  std::vector<int> order(images);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<int> fold(images);
  for (int k = 0; k < images; ++k) fold[order[k]] = k % std::max(1, folds);
  return fold;
}

Eigen::MatrixXd Rows(const Eigen::MatrixXd& x, const std::vector<int>& rows) {
  Eigen::MatrixXd out(rows.size(), x.cols());
  for (size_t i = 0; i < rows.size(); ++i) out.row(i) = x.row(rows[i]);
  return out;
}

template <class T>
std::vector<T> Pick(const std::vector<T>& v, const std::vector<int>& rows) {
  std::vector<T> out;
  for (int r : rows) out.push_back(v[r]);
  return out;
}

Eigen::Vector3d PredictNormal(const std::array<Learned, 3>& f, const Eigen::VectorXd& x) {
  const Eigen::Vector3d n(f[0](x), f[1](x), f[2](x));
  return n.norm() > 1e-9 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d(0, 0, -1);
}

std::array<Learned, 3> TrainNormal(const TrainOptions& o, const internal::LearnerSetting& setting,
                                   const Eigen::MatrixXd& x, const std::vector<Eigen::Vector3d>& normals) {
  std::array<Learned, 3> f;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> t;
    for (const auto& n : normals) t.push_back(n[c]);
    f[c] = internal::TrainRegressor(o, setting, x, Eigen::Map<const Eigen::VectorXd>(t.data(), x.rows()));
  }
  return f;
}

// Splits row indices into (train, test) for fold `k`.
void Split(const std::vector<int>& image_of_row, const std::vector<int>& fold_of_image, int k, std::vector<int>* train,
           std::vector<int>* test) {
  train->clear();
  test->clear();
  for (size_t r = 0; r < image_of_row.size(); ++r) {
    (fold_of_image[image_of_row[r]] == k ? test : train)->push_back(static_cast<int>(r));
  }
}

struct SettingChoice {
  internal::LearnerSetting setting;
  double loss = -1;  // mean cross-validated loss per test row; -1 without cross-validation
};

// The setting (kernel width, ...) among `settings` with the lowest mean loss over the folds (grouped by image).
// `fold_loss(train, test, setting)` trains on the rows `train` and returns the summed loss over the rows `test`,
// or nothing to skip the fold. With fewer than 2 folds (or no rows), the first setting.
template <class FoldLoss>
SettingChoice ChooseSetting(const std::vector<internal::LearnerSetting>& settings, double dims, int folds,
                            const std::vector<int>& image_of_row, const std::vector<int>& fold_of_image,
                            const char* what, FoldLoss fold_loss) {
  SettingChoice best{settings.front(), -1};
  if (folds < 2 || image_of_row.empty()) return best;
  for (const internal::LearnerSetting& g : settings) {
    double sum = 0;
    size_t tested = 0;
    std::vector<int> train, test;
    for (int f = 0; f < folds; ++f) {
      Split(image_of_row, fold_of_image, f, &train, &test);
      if (train.empty() || test.empty()) continue;
      const std::optional<double> loss = fold_loss(train, test, g);
      if (!loss) continue;
      sum += *loss;
      tested += test.size();
    }
    if (tested == 0) continue;
    const double mean = sum / tested;
    PDVO_LOG(Info) << "cross-validation: " << g.Describe(dims) << ", " << what << " " << mean;
    if (best.loss < 0 || mean < best.loss) best = {g, mean};
  }
  return best;
}

// Each salient point's MaskLabel in the annotation (points at the working size of `image`).
std::vector<uint8_t> PointLabels(const std::vector<cv::Point2f>& points, const AnnotatedImage& image) {
  const cv::Mat label = Rasterise(image.annotation, image.image.size()).label;
  std::vector<uint8_t> out;
  for (const cv::Point2f& p : points) {
    out.push_back(label.at<uint8_t>(std::clamp(static_cast<int>(std::lround(p.y)), 0, label.rows - 1),
                                    std::clamp(static_cast<int>(std::lround(p.x)), 0, label.cols - 1)));
  }
  return out;
}

// Adds each annotated point's two words (colour words after the gradient words) to its label's counts.
void CountWords(const ImageWords& words, const std::vector<uint8_t>& labels, int gradient_words,
                Eigen::VectorXd* plane_counts, Eigen::VectorXd* non_plane_counts) {
  for (size_t p = 0; p < words.size(); ++p) {
    if (labels[p] == kMaskUnknown) continue;
    Eigen::VectorXd& counts = labels[p] == kMaskPlane ? *plane_counts : *non_plane_counts;
    counts(words.gradient[p]) += 1;
    counts(gradient_words + words.colour[p]) += 1;
  }
}

}  // namespace

bool RvmOptions::Check() const {
  PDVO_CHECK_OPTION(!gammas.empty());
  PDVO_CHECK_OPTION(std::all_of(gammas.begin(), gammas.end(), [](double g) { return g > 0; }));
  PDVO_CHECK_OPTION(epsilon > 0 && max_iterations >= 1);
  return true;
}

bool SvmOptions::Check() const {
  PDVO_CHECK_OPTION(!gammas.empty() && !c.empty() && epsilon >= 0);
  PDVO_CHECK_OPTION(std::all_of(gammas.begin(), gammas.end(), [](double g) { return g > 0; }));
  PDVO_CHECK_OPTION(std::all_of(c.begin(), c.end(), [](double v) { return v > 0; }));
  return true;
}

bool KnnOptions::Check() const {
  PDVO_CHECK_OPTION(!k.empty());
  PDVO_CHECK_OPTION(std::all_of(k.begin(), k.end(), [](double v) { return v >= 1 && v == std::floor(v); }));
  return true;
}

bool TreesOptions::Check() const {
  PDVO_CHECK_OPTION(trees >= 1 && min_samples >= 1 && !max_depth.empty());
  PDVO_CHECK_OPTION(
      std::all_of(max_depth.begin(), max_depth.end(), [](double v) { return v >= 1 && v == std::floor(v); }));
  return true;
}

bool TrainOptions::Check() const {
  PDVO_CHECK_OPTION(recogniser.Check() && regions.Check() && topics.Check() && rvm.Check() && svm.Check() &&
                    knn.Check() && trees.Check());
  PDVO_CHECK_OPTION(gradient_words >= 2 && colour_words >= 2);
  PDVO_CHECK_OPTION(vocabulary_samples >= std::max(gradient_words, colour_words));
  PDVO_CHECK_OPTION(kmeans_iterations >= 1);
  PDVO_CHECK_OPTION(max_regions_per_class >= 2 && max_normal_regions >= 0);
  PDVO_CHECK_OPTION(classifiers >= 1);
  PDVO_CHECK_OPTION(layout_weight > 0);
  return true;
}

Eigen::VectorXd CountWordPlaneLogOdds(const PlaneModel& model, const std::vector<std::string>& files) {
  PDVO_THROW_CHECK(!files.empty(), InvalidArgument, "word log-odds: no annotation files");
  const int gradient_words = model.gradient_words.size();
  Eigen::VectorXd plane_counts = Eigen::VectorXd::Zero(gradient_words + model.colour_words.size());
  Eigen::VectorXd non_plane_counts = plane_counts;
  Progress progress("counting words", files.size());
  for (const std::string& file : files) {
    const AnnotatedImage a = ReadAnnotatedImage(file, model.options.working_width);
    const Features features = ExtractFeatures(a.image, model.options.features);
    CountWords(QuantiseFeatures(features, model.gradient_words, model.colour_words), PointLabels(features.points, a),
               gradient_words, &plane_counts, &non_plane_counts);
    progress.Step();
  }
  progress.Finish();
  return WordPlaneLogOdds(plane_counts, non_plane_counts);
}

PlaneModel TrainModel(const std::vector<std::string>& files, const TrainOptions& o, uint64_t seed, int folds,
                      const std::string& data_description) {
  CheckOptionsOrThrow(o, "training options");
  PDVO_THROW_CHECK(!files.empty(), InvalidArgument, "train: no annotation files");
  PDVO_THROW_CHECK(folds >= 1, InvalidArgument, "train: --cv must be at least 1");
  std::mt19937_64 rng(seed);
  const Clock::time_point start = Clock::now();

  // 1. Images -> salient points, descriptors and sampled regions.
  Clock::time_point stage = Clock::now();
  std::vector<Features> features;
  std::vector<std::vector<uint8_t>> point_labels;  // per image and salient point: its MaskLabel
  std::vector<SampledRegion> regions;
  {
    Progress progress("describing images", files.size());
    for (size_t i = 0; i < files.size(); ++i) {
      const AnnotatedImage a = ReadAnnotatedImage(files[i], o.recogniser.working_width);
      features.push_back(ExtractFeatures(a.image, o.recogniser.features));
      point_labels.push_back(PointLabels(features.back().points, a));
      const EdgePlanes edges = FindEdgePlanes(a.image, a.camera, o.recogniser.vanishing);
      for (LabelledRegion& r : SampleRegions(a.annotation, a.image.size(), o.regions, rng)) {
        const Eigen::Vector2d structure = EdgeStructure(edges, r.region, o.recogniser.vanishing);
        regions.push_back({static_cast<int>(i), std::move(r), {}, structure});
      }
      progress.Step();
    }
  }
  size_t descriptor_count = 0;
  for (const Features& f : features) descriptor_count += f.size();
  PDVO_LOG(Info) << "[time] described " << files.size() << " images (" << descriptor_count << " points, "
                 << regions.size() << " regions) in " << Since(stage) << " s";

  // 2. Vocabularies.
  stage = Clock::now();
  PDVO_THROW_CHECK(static_cast<int>(descriptor_count) >= std::max(o.gradient_words, o.colour_words), InvalidArgument,
                   "train: " << descriptor_count << " salient points in all images, fewer than the vocabulary size");
  const Vocabulary gradient_words = Vocabulary::Build(DrawDescriptors(features, true, o.vocabulary_samples, rng),
                                                      o.gradient_words, seed, o.kmeans_iterations);
  const Vocabulary colour_words = Vocabulary::Build(DrawDescriptors(features, false, o.vocabulary_samples, rng),
                                                    o.colour_words, seed + 1, o.kmeans_iterations);
  std::vector<ImageWords> words;
  for (const Features& f : features) words.push_back(QuantiseFeatures(f, gradient_words, colour_words));
  features.clear();
  // Each word's points on annotated planes and non-planes: the detector's prior on a point's planarity.
  Eigen::VectorXd plane_counts = Eigen::VectorXd::Zero(o.gradient_words + o.colour_words);
  Eigen::VectorXd non_plane_counts = plane_counts;
  for (size_t i = 0; i < words.size(); ++i)
    CountWords(words[i], point_labels[i], o.gradient_words, &plane_counts, &non_plane_counts);
  PDVO_LOG(Info) << "[time] vocabularies of " << o.gradient_words << " gradient and " << o.colour_words
                 << " colour words in " << Since(stage) << " s";

  // 3. Region words; regions with too few points are dropped; classes balanced; normals drawn.
  std::vector<int> planes, non_planes, normals;
  for (size_t k = 0; k < regions.size(); ++k) {
    SampledRegion& r = regions[k];
    r.words = CollectRegionWords(words[r.image], r.labelled.region, o.gradient_words, o.colour_words);
    r.words.edge_structure = r.edge_structure;
    if (r.words.size() < o.recogniser.min_points) continue;
    (r.labelled.planar ? planes : non_planes).push_back(static_cast<int>(k));
    if (r.labelled.planar && r.labelled.normal) normals.push_back(static_cast<int>(k));
  }
  PDVO_THROW_CHECK(!planes.empty(), InvalidArgument,
                   "train: no plane regions with at least " << o.recogniser.min_points << " salient points");
  PDVO_THROW_CHECK(!non_planes.empty(), InvalidArgument,
                   "train: no non-plane regions with at least " << o.recogniser.min_points << " salient points");
  const size_t per_class = std::min({planes.size(), non_planes.size(), static_cast<size_t>(o.max_regions_per_class)});
  PDVO_LOG(Info) << "regions with enough points: " << planes.size() << " planes (" << normals.size()
                 << " with normals), " << non_planes.size() << " non-planes";
  std::shuffle(normals.begin(), normals.end(), rng);
  if (normals.size() > static_cast<size_t>(o.max_normal_regions)) normals.resize(o.max_normal_regions);
  std::sort(normals.begin(), normals.end());
  // Each classifier's draw: per_class regions of each class, sorted.
  std::vector<std::vector<int>> draws;
  for (int c = 0; c < o.classifiers; ++c) {
    std::vector<int> draw;
    for (std::vector<int>* pool : {&planes, &non_planes}) {
      std::shuffle(pool->begin(), pool->end(), rng);
      draw.insert(draw.end(), pool->begin(), pool->begin() + static_cast<std::ptrdiff_t>(per_class));
    }
    std::sort(draw.begin(), draw.end());
    draws.push_back(std::move(draw));
  }
  // The topics and the standardisation are learned on the first draw and the normals' regions (the
  // representation of a single classifier); the other draws only train classifiers.
  std::vector<int> basis;
  std::set_union(draws.front().begin(), draws.front().end(), normals.begin(), normals.end(), std::back_inserter(basis));
  std::vector<int> used = basis;  // every region that trains something
  for (const std::vector<int>& draw : draws) used.insert(used.end(), draw.begin(), draw.end());
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  PDVO_LOG(Info) << "training regions: " << o.classifiers << " draws of " << per_class << " planes and " << per_class
                 << " non-planes, " << normals.size() << " with normals, " << used.size() << " in all";

  // 4. Topics by orthogonal NMF of the training regions' word histograms.
  stage = Clock::now();
  const int total_words = o.gradient_words + o.colour_words;
  Eigen::MatrixXd histograms(total_words, basis.size());
  for (size_t k = 0; k < basis.size(); ++k) histograms.col(k) = regions[basis[k]].words.histogram;
  OnmfOptions topic_options = o.topics;
  topic_options.seed = seed;
  PDVO_THROW_CHECK(
      static_cast<int>(basis.size()) >= topic_options.topics, InvalidArgument,
      "train: " << basis.size() << " training regions, fewer than the " << topic_options.topics << " topics");
  const OnmfResult topics = FactoriseOrthogonal(histograms, topic_options);
  PDVO_LOG(Info) << "[time] " << topic_options.topics << " topics (relative error "
                 << (topics.errors.empty() ? 0.0 : topics.errors.back()) << ") in " << Since(stage) << " s";

  // 5. Spatiogram features, standardised.
  stage = Clock::now();
  std::vector<Eigen::VectorXd> raw(regions.size());
  for (int k : used) raw[k] = RegionFeature(regions[k].words, topics.basis, o.recogniser.topic_iterations);
  const Eigen::Index dims = raw[used.front()].size();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(dims), var = Eigen::VectorXd::Zero(dims);
  for (int k : basis) mean += raw[k];
  mean /= basis.size();
  for (int k : basis) var += (raw[k] - mean).cwiseAbs2();
  Eigen::VectorXd scale = (var / basis.size()).cwiseSqrt().cwiseMax(1e-6);
  scale.tail(kLayoutDims) /= o.layout_weight;
  auto matrix_of = [&](const std::vector<int>& rows) {
    Eigen::MatrixXd x(rows.size(), dims);
    for (size_t i = 0; i < rows.size(); ++i) x.row(i) = (raw[rows[i]] - mean).cwiseQuotient(scale).transpose();
    return x;
  };
  PDVO_LOG(Info) << "[time] " << used.size() << " region features (" << dims << "-D) in " << Since(stage) << " s";

  // 6. Classifiers and normal regressors, with their settings chosen by cross-validation grouped by image.
  const std::vector<int> fold_of_image = FoldOfImage(static_cast<int>(files.size()), folds, rng);
  const std::vector<internal::LearnerSetting> settings = internal::Settings(o, static_cast<double>(dims));
  const char* const vectors = o.classifier == LearnerKind::kRvm   ? "relevance vectors"
                              : o.classifier == LearnerKind::kSvm ? "support vectors"
                              : o.classifier == LearnerKind::kKnn ? "samples"
                                                                  : "tree nodes";

  stage = Clock::now();
  auto labels_of = [&](const std::vector<int>& rows) {
    std::vector<double> labels;
    for (int k : rows) labels.push_back(regions[k].labelled.planar ? 1.0 : -1.0);
    return labels;
  };
  const Eigen::MatrixXd xc = matrix_of(draws.front());
  const std::vector<double> labels = labels_of(draws.front());
  std::vector<int> image_c;
  for (int k : draws.front()) image_c.push_back(regions[k].image);
  // Loss: the share of misclassified test rows.
  const SettingChoice classifier_choice =
      ChooseSetting(settings, static_cast<double>(dims), folds, image_c, fold_of_image, "classifier error",
                    [&](const auto& train, const auto& test, const internal::LearnerSetting& g) {
                      const std::vector<double> train_labels = Pick(labels, train);
                      std::optional<double> errors;
                      if (std::count(train_labels.begin(), train_labels.end(), 1.0) == 0 ||
                          std::count(train_labels.begin(), train_labels.end(), -1.0) == 0) {
                        return errors;  // a fold without both classes says nothing
                      }
                      const Learned fn = internal::TrainClassifier(o, g, Rows(xc, train), train_labels);
                      errors = 0.0;
                      for (int r : test) *errors += (fn(xc.row(r).transpose()) >= 0.5) != (labels[r] > 0);
                      return errors;
                    });
  const internal::LearnerSetting& best = classifier_choice.setting;
  PlaneModel model;
  std::ostringstream sizes;
  for (const std::vector<int>& draw : draws) {
    model.classifiers.push_back(internal::TrainClassifier(o, best, matrix_of(draw), labels_of(draw)));
    sizes << (sizes.tellp() > 0 ? "/" : "") << model.classifiers.back().size;
  }
  PDVO_LOG(Info) << "[time] " << draws.size() << " " << OptionName(o.classifier) << " classifiers ("
                 << best.Describe(static_cast<double>(dims)) << ", " << sizes.str() << " " << vectors << ") in "
                 << Since(stage) << " s";

  stage = Clock::now();
  const Eigen::MatrixXd xn = matrix_of(normals);
  std::vector<Eigen::Vector3d> targets;
  std::vector<int> image_n;
  for (int k : normals) {
    targets.push_back(*regions[k].labelled.normal);
    image_n.push_back(regions[k].image);
  }
  // Loss: the angle between the true and the predicted normal, in degrees.
  const SettingChoice normal_choice =
      ChooseSetting(settings, static_cast<double>(dims), folds, image_n, fold_of_image, "normal error (deg)",
                    [&](const auto& train, const auto& test, const internal::LearnerSetting& g) {
                      const auto fn = TrainNormal(o, g, Rows(xn, train), Pick(targets, train));
                      std::optional<double> sum = 0.0;
                      for (int r : test) *sum += AngleDegrees(targets[r], PredictNormal(fn, xn.row(r).transpose()));
                      return sum;
                    });
  const internal::LearnerSetting& best_normal = normal_choice.setting;
  if (!normals.empty()) {
    model.normal = TrainNormal(o, best_normal, xn, targets);
  } else {
    PDVO_THROW_CHECK(
        o.classifier == LearnerKind::kRvm, InvalidArgument,
        "train: no plane regions with normals, which the " << OptionName(o.classifier) << " regressors need");
    PDVO_LOG(Warning) << "no plane regions with normals: the model predicts no orientation";
    for (Learned& f : model.normal) {
      f = Learned::Rvm(RvmFunction(), false);
      f.rvm.gamma = best_normal.gamma;
    }
  }
  PDVO_LOG(Info) << "[time] normal regressors (" << best_normal.Describe(static_cast<double>(dims)) << ", "
                 << model.normal[0].size << "+" << model.normal[1].size << "+" << model.normal[2].size << " " << vectors
                 << ") in " << Since(stage) << " s";

  model.options = o.recogniser;
  model.gradient_words = gradient_words;
  model.colour_words = colour_words;
  model.topics = topics.basis;
  model.word_plane_log_odds = WordPlaneLogOdds(plane_counts, non_plane_counts);
  model.feature_mean = mean;
  model.feature_scale = scale;
  model.card.data = data_description;
  model.card.images = static_cast<int>(files.size());
  model.card.plane_regions = static_cast<int>(per_class);
  model.card.non_plane_regions = static_cast<int>(per_class);
  model.card.normal_regions = static_cast<int>(normals.size());
  model.card.folds = folds;
  model.card.cv_accuracy = classifier_choice.loss < 0 ? 0 : 1 - classifier_choice.loss;
  model.card.cv_normal_error = std::max(0.0, normal_choice.loss);
  model.card.seed = static_cast<int>(seed);
  PDVO_LOG(Info) << "[time] trained in " << Since(start) << " s";
  return model;
}

}  // namespace pdvo
