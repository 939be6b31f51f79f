#include "pdvo/infer/model.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core/eigen.hpp>
#include <string_view>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {

constexpr const char* kEndMarker = "end_of_model";
constexpr std::string_view kChecksumPrefix = "# crc32: ";

std::string Crc32Hex(std::string_view bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  for (size_t at = 0; at < bytes.size(); at += 1 << 30) {  // zlib takes lengths as uInt
    const size_t n = std::min<size_t>(bytes.size() - at, 1 << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), static_cast<uInt>(n));
  }
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08lx", crc & 0xffffffffUL);
  return hex;
}

// Where the last line of `text` starts (the checksum line, if there is one).
size_t LastLineStart(std::string_view text) {
  const size_t end = !text.empty() && text.back() == '\n' ? text.size() - 1 : text.size();
  const size_t newline = end == 0 ? std::string_view::npos : text.rfind('\n', end - 1);
  return newline == std::string_view::npos ? 0 : newline + 1;
}

// Whether `text` ends with a checksum line; throws when it does and the checksum does not match.
bool VerifyChecksum(std::string_view text, const std::string& where) {
  const size_t start = LastLineStart(text);
  std::string_view line = text.substr(start);
  if (!line.starts_with(kChecksumPrefix)) return false;
  line.remove_prefix(kChecksumPrefix.size());
  if (line.ends_with('\n')) line.remove_suffix(1);
  const std::string actual = Crc32Hex(text.substr(0, start));
  PDVO_THROW_CHECK(line == actual, FormatError,
                   where << ": checksum mismatch (the file is corrupt or was edited: its content gives crc32 " << actual
                         << ", its last line says " << line << ")");
  return true;
}

cv::Mat ToMat(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

// Single precision: the relevance vectors are most of a model's bytes.
cv::Mat ToFloatMat(const Eigen::MatrixXd& m) {
  cv::Mat out;
  ToMat(m).convertTo(out, CV_32F);
  return out;
}

Eigen::MatrixXd ReadMatrix(const cv::FileNode& node, const std::string& where, const std::string& key) {
  cv::Mat m;
  node[key] >> m;
  PDVO_THROW_CHECK(!m.empty() && (m.type() == CV_64F || m.type() == CV_32F), FormatError,
                   where << ": missing or malformed '" << key << "'");
  m.convertTo(m, CV_64F);
  Eigen::MatrixXd out;
  cv::cv2eigen(m, out);
  PDVO_THROW_CHECK(out.allFinite(), FormatError, where << ": '" << key << "' holds NaN or infinite values");
  return out;
}

// `name` empty: an element of a sequence.
void WriteRvm(cv::FileStorage& fs, const std::string& name, const RvmFunction& f) {
  if (!name.empty()) fs << name;
  fs << "{"
     << "gamma" << f.gamma << "bias" << f.bias << "relevance_vectors" << f.size();
  fs << "weights" << ToMat(f.weights) << "vectors" << ToFloatMat(f.vectors) << "}";
}

RvmFunction ReadRvm(const cv::FileNode& node, const std::string& where, int dims) {
  PDVO_THROW_CHECK(node.isMap(), FormatError, where << ": missing");
  RvmFunction f;
  f.gamma = static_cast<double>(node["gamma"]);
  f.bias = static_cast<double>(node["bias"]);
  f.weights = ReadMatrix(node, where, "weights");
  f.vectors = ReadMatrix(node, where, "vectors");
  PDVO_THROW_CHECK(f.gamma > 0 && std::isfinite(f.bias) && f.weights.cols() == 1 &&
                       f.vectors.rows() == f.weights.rows() && f.vectors.cols() == dims &&
                       static_cast<int>(node["relevance_vectors"]) == f.size(),
                   FormatError, where << ": malformed RVM (sizes do not agree)");
  return f;
}

cv::Mat ToFloatRows(const Eigen::MatrixXd& rows) { return ToFloatMat(rows); }

// A member of `classifiers` or a normal regressor. RVM: as version 3 wrote it; the others: their kind, their
// size, Platt's parameters (SVM classifier) and the OpenCV model as it writes itself.
void WriteLearned(cv::FileStorage& fs, const std::string& name, const Learned& f) {
  if (f.kind == LearnerKind::kRvm) return WriteRvm(fs, name, f.rvm);
  if (!name.empty()) fs << name;
  fs << "{"
     << "kind" << OptionName(f.kind) << "size" << f.size;
  if (f.kind == LearnerKind::kSvm && f.classifier) fs << "platt_a" << f.platt_a << "platt_b" << f.platt_b;
  fs << "model"
     << "{";
  f.ml->write(fs);
  fs << "}"
     << "}";
}

Learned ReadLearned(const cv::FileNode& node, const std::string& where, int dims, LearnerKind kind, bool classifier) {
  if (kind == LearnerKind::kRvm) return Learned::Rvm(ReadRvm(node, where, dims), classifier);
  PDVO_THROW_CHECK(node.isMap(), FormatError, where << ": missing");
  PDVO_THROW_CHECK(
      static_cast<std::string>(node["kind"]) == OptionName(kind), FormatError,
      where << ": a " << static_cast<std::string>(node["kind"]) << " model in a " << OptionName(kind) << " file");
  Learned f;
  f.kind = kind;
  f.classifier = classifier;
  f.size = static_cast<int>(node["size"]);
  if (kind == LearnerKind::kSvm && classifier) {
    f.platt_a = static_cast<double>(node["platt_a"]);
    f.platt_b = static_cast<double>(node["platt_b"]);
  }
  const cv::FileNode model = node["model"];
  PDVO_THROW_CHECK(model.isMap(), FormatError, where << ": no model");
  try {
    if (kind == LearnerKind::kSvm) f.ml = cv::ml::SVM::create();
    if (kind == LearnerKind::kKnn) f.ml = cv::ml::KNearest::create();
    if (kind == LearnerKind::kTrees) f.ml = cv::ml::RTrees::create();
    f.ml->read(model);
  } catch (const cv::Exception& e) {
    PDVO_THROW(FormatError, where << ": malformed " << OptionName(kind) << " model");
  }
  PDVO_THROW_CHECK(f.ml->isTrained() && f.ml->getVarCount() == dims && f.size >= 0 && std::isfinite(f.platt_a) &&
                       std::isfinite(f.platt_b),
                   FormatError, where << ": malformed " << OptionName(kind) << " model (sizes do not agree)");
  return f;
}

// PlaneModel::FromYaml without its translation of OpenCV errors.
PlaneModel ParseModel(const std::string& text, const std::string& where) {
  const bool checked = VerifyChecksum(text, where);
  cv::FileStorage fs = OpenYamlText(text, where);
  PDVO_THROW_CHECK(static_cast<std::string>(fs["format"]) == kModelFormat, FormatError,
                   where << ": not a " << kModelFormat << " file");
  const int version = static_cast<int>(fs["version"]);
  PDVO_THROW_CHECK(version >= 3 && version <= kModelVersion, FormatError,
                   where << ": model version " << version << ", this build reads versions 3 to " << kModelVersion
                         << " (retrain with pdvo train)");
  PDVO_THROW_CHECK(checked || version < 5, FormatError,
                   where << ": no checksum line (a version " << version << " model ends with '" << kChecksumPrefix
                         << "...'): the file was cut short or edited");
  if (!checked) {
    PDVO_LOG(Warning) << where << ": a version " << version
                      << " model has no checksum, so its integrity cannot be checked (pdvo train writes version "
                      << kModelVersion << ")";
  }
  LearnerKind learner = LearnerKind::kRvm;  // version 3: RVMs
  if (version >= 4) {
    const std::string name = static_cast<std::string>(fs["learner"]);
    bool known = false;
    for (const auto& [kind, kind_name] : OptionNames(LearnerKind{})) {
      if (name == kind_name) learner = kind, known = true;
    }
    PDVO_THROW_CHECK(known, FormatError, where << ": unknown learner '" << name << "'");
  }
  PDVO_THROW_CHECK(static_cast<std::string>(fs[kEndMarker]) == kModelFormat, FormatError,
                   where << ": truncated model (no end marker)");
  PlaneModel m;
  ReadOptions(fs["options"], m.options, where + ": options");
  CheckOptionsOrThrow(m.options, where + ": options");
  const cv::FileNode card = fs["card"];
  PDVO_THROW_CHECK(card.isMap(), FormatError, where << ": missing card");
  m.card.data = static_cast<std::string>(card["data"]);
  m.card.images = static_cast<int>(card["images"]);
  m.card.plane_regions = static_cast<int>(card["plane_regions"]);
  m.card.non_plane_regions = static_cast<int>(card["non_plane_regions"]);
  m.card.normal_regions = static_cast<int>(card["normal_regions"]);
  m.card.folds = static_cast<int>(card["folds"]);
  m.card.cv_accuracy = static_cast<double>(card["cv_accuracy"]);
  m.card.cv_normal_error = static_cast<double>(card["cv_normal_error_deg"]);
  m.card.seed = static_cast<int>(card["seed"]);
  m.card.training_options = static_cast<std::string>(card["training_options"]);
  m.card.pdvo_version = static_cast<std::string>(card["pdvo_version"]);
  m.card.git_commit = static_cast<std::string>(card["git_commit"]);
  m.card.word_prior = static_cast<std::string>(card["word_prior"]);
  m.gradient_words = Vocabulary::Read(fs["gradient_words"], where + ": gradient_words");
  m.colour_words = Vocabulary::Read(fs["colour_words"], where + ": colour_words");
  PDVO_THROW_CHECK(m.gradient_words.dims() == kGradientDims && m.colour_words.dims() == kColourDims, FormatError,
                   where << ": vocabularies of the wrong descriptor size");
  m.topics = ReadMatrix(fs.root(), where, "topics");
  PDVO_THROW_CHECK(m.topics.rows() == m.gradient_words.size() + m.colour_words.size() && (m.topics.array() >= 0).all(),
                   FormatError, where << ": the topic basis does not match the vocabularies");
  if (!fs["word_plane_log_odds"].empty()) {  // version 6 models trained since it was added
    m.word_plane_log_odds = ReadMatrix(fs.root(), where, "word_plane_log_odds");
    PDVO_THROW_CHECK(m.word_plane_log_odds.size() == m.topics.rows() && m.word_plane_log_odds.allFinite(), FormatError,
                     where << ": the word log-odds do not match the vocabularies");
  }
  m.feature_mean = ReadMatrix(fs.root(), where, "feature_mean");
  m.feature_scale = ReadMatrix(fs.root(), where, "feature_scale");
  const int dims = static_cast<int>(m.feature_mean.rows());
  PDVO_THROW_CHECK(m.feature_mean.cols() == 1 && m.feature_scale.rows() == dims && m.feature_scale.cols() == 1 &&
                       (m.feature_scale.array() > 0).all(),
                   FormatError, where << ": malformed feature standardisation");
  const cv::FileNode classifiers = fs["classifiers"];
  PDVO_THROW_CHECK(classifiers.isSeq() && classifiers.size() > 0, FormatError, where << ": no classifiers");
  for (size_t i = 0; i < classifiers.size(); ++i) {
    const std::string what = where + ": classifier " + std::to_string(i);
    m.classifiers.push_back(ReadLearned(classifiers[static_cast<int>(i)], what, dims, learner, true));
  }
  m.normal[0] = ReadLearned(fs["normal_x"], where + ": normal_x", dims, learner, false);
  m.normal[1] = ReadLearned(fs["normal_y"], where + ": normal_y", dims, learner, false);
  m.normal[2] = ReadLearned(fs["normal_z"], where + ": normal_z", dims, learner, false);
  return m;
}

}  // namespace

Learned Learned::Rvm(RvmFunction f, bool classifier) {
  Learned l;
  l.kind = LearnerKind::kRvm;
  l.classifier = classifier;
  l.size = f.size();
  l.rvm = std::move(f);
  return l;
}

Eigen::VectorXd Learned::Evaluate(const Eigen::MatrixXd& rows) const {
  if (kind == LearnerKind::kRvm) {
    const Eigen::VectorXd v = rvm.Evaluate(rows);
    return classifier ? Eigen::VectorXd((1.0 + (-v).array().exp()).inverse().matrix()) : v;
  }
  Eigen::VectorXd out(rows.rows());
  if (rows.rows() == 0) return out;
  const cv::Mat x = ToFloatRows(rows);
  cv::Mat values;
  if (kind == LearnerKind::kSvm) {
    ml->predict(x, values, classifier ? cv::ml::StatModel::RAW_OUTPUT : 0);
    for (int i = 0; i < x.rows; ++i) {
      const double f = values.at<float>(i);
      out[i] = classifier ? 1.0 / (1.0 + std::exp(platt_a * f + platt_b)) : f;
    }
  } else if (kind == LearnerKind::kKnn) {
    const auto knn = ml.dynamicCast<cv::ml::KNearest>();
    const int k = knn->getDefaultK();
    cv::Mat neighbours;
    knn->findNearest(x, k, values, neighbours);
    for (int i = 0; i < x.rows; ++i) {
      out[i] = classifier ? (cv::sum(neighbours.row(i))[0] + 1.0) / (k + 2.0) : values.at<float>(i);
    }
  } else if (classifier) {  // trees: the share of votes for the plane class (label 1)
    cv::Mat votes;
    ml.dynamicCast<cv::ml::RTrees>()->getVotes(x, votes, 0);
    int plane = -1;
    for (int c = 0; c < votes.cols; ++c) plane = votes.at<int>(0, c) == 1 ? c : plane;
    for (int i = 0; i < x.rows; ++i) {
      const double all = cv::sum(votes.row(i + 1))[0];
      out[i] = plane < 0 || all <= 0 ? 0.0 : votes.at<int>(i + 1, plane) / all;
    }
  } else {
    ml->predict(x, values);
    for (int i = 0; i < x.rows; ++i) out[i] = values.at<float>(i);
  }
  return out;
}

double Learned::operator()(const Eigen::VectorXd& x) const {
  if (kind != LearnerKind::kRvm) return Evaluate(x.transpose())[0];
  const double v = rvm(x);
  return classifier ? 1.0 / (1.0 + std::exp(-v)) : v;
}

double RvmFunction::operator()(const Eigen::VectorXd& x) const {
  double sum = -bias;
  for (Eigen::Index i = 0; i < vectors.rows(); ++i) {
    sum += weights[i] * std::exp(-gamma * (vectors.row(i).transpose() - x).squaredNorm());
  }
  return sum;
}

Eigen::VectorXd RvmFunction::Evaluate(const Eigen::MatrixXd& rows) const {
  return RvmBank({this}).Evaluate(rows).col(0);
}

RvmBank::RvmBank(const std::vector<const RvmFunction*>& functions)
    : bias_(static_cast<Eigen::Index>(functions.size())), functions_(static_cast<int>(functions.size())) {
  // Per kernel width: the distinct vectors in order of first use (exact equality: they are rows of one training
  // set) and each function's weight on each.
  struct Entry {
    size_t vector;
    int function;
    double weight;
  };
  struct Building {
    double gamma;
    std::vector<Eigen::VectorXf> vectors;
    std::vector<Entry> entries;
  };
  std::vector<Building> building;
  Eigen::Index dims = 0;
  for (int f = 0; f < functions_; ++f) {
    const RvmFunction& rvm = *functions[f];
    bias_[f] = rvm.bias;
    auto group =
        std::find_if(building.begin(), building.end(), [&](const Building& g) { return g.gamma == rvm.gamma; });
    if (group == building.end()) group = building.insert(building.end(), Building{rvm.gamma, {}, {}});
    for (Eigen::Index i = 0; i < rvm.vectors.rows(); ++i) {
      const Eigen::VectorXf v = rvm.vectors.row(i).cast<float>();
      const size_t at = std::find(group->vectors.begin(), group->vectors.end(), v) - group->vectors.begin();
      if (at == group->vectors.size()) group->vectors.push_back(v);
      group->entries.push_back({at, f, rvm.weights[i]});
      dims = rvm.vectors.cols();
    }
  }
  for (const Building& b : building) {
    if (b.vectors.empty()) continue;  // constant functions: their bias is all
    Group& g = groups_.emplace_back();
    g.gamma = b.gamma;
    g.vectors.resize(static_cast<Eigen::Index>(b.vectors.size()), dims);
    for (size_t i = 0; i < b.vectors.size(); ++i) g.vectors.row(static_cast<Eigen::Index>(i)) = b.vectors[i];
    g.norms = g.vectors.cast<double>().rowwise().squaredNorm();
    g.weights = Eigen::MatrixXd::Zero(g.vectors.rows(), functions_);
    for (const Entry& e : b.entries) g.weights(static_cast<Eigen::Index>(e.vector), e.function) += e.weight;
  }
}

Eigen::MatrixXd RvmBank::Evaluate(const Eigen::MatrixXd& rows) const {
  Eigen::MatrixXd out = -bias_.replicate(rows.rows(), 1);
  const Eigen::MatrixXf rows_float = rows.cast<float>();
  const Eigen::VectorXd row_norms = rows_float.cast<double>().rowwise().squaredNorm();
  Eigen::MatrixXd kernel;
  for (const Group& g : groups_) {
    kernel = -2.0 * (rows_float * g.vectors.transpose()).cast<double>();
    kernel.colwise() += row_norms;
    kernel.rowwise() += g.norms.transpose();
    kernel = (-g.gamma * kernel.array().max(0.0)).exp().matrix();
    out.noalias() += kernel * g.weights;
  }
  return out;
}

bool RecogniserOptions::Check() const {
  PDVO_CHECK_OPTION(working_width == 0 || (working_width >= 32 && working_width <= kMaxImageSide));
  PDVO_CHECK_OPTION(features.Check());
  PDVO_CHECK_OPTION(min_points >= 1);
  PDVO_CHECK_OPTION(topic_iterations >= 1);
  PDVO_CHECK_OPTION(vanishing.Check());
  return true;
}

std::string PlaneModel::ToYaml() const {
  // Matrices in base64 (raw bytes: a third of the size of their text, and exactly the same values).
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::BASE64);
  fs << "format" << kModelFormat << "version" << kModelVersion << "learner" << OptionName(learner());
  fs << "options"
     << "{";
  WriteOptions(fs, options);
  fs << "}";
  fs << "card"
     << "{"
     << "data" << card.data << "images" << card.images << "plane_regions" << card.plane_regions << "non_plane_regions"
     << card.non_plane_regions << "normal_regions" << card.normal_regions << "folds" << card.folds << "cv_accuracy"
     << card.cv_accuracy << "cv_normal_error_deg" << card.cv_normal_error << "seed" << card.seed << "training_options"
     << card.training_options << "pdvo_version" << card.pdvo_version << "git_commit" << card.git_commit;
  if (!card.word_prior.empty()) fs << "word_prior" << card.word_prior;
  fs << "}";
  gradient_words.Write(fs, "gradient_words");
  colour_words.Write(fs, "colour_words");
  fs << "topics" << ToMat(topics);
  if (word_plane_log_odds.size() > 0) fs << "word_plane_log_odds" << ToMat(word_plane_log_odds);
  fs << "feature_mean" << ToMat(feature_mean) << "feature_scale" << ToMat(feature_scale);
  fs << "classifiers"
     << "[";
  for (const Learned& f : classifiers) WriteLearned(fs, "", f);
  fs << "]";
  WriteLearned(fs, "normal_x", normal[0]);
  WriteLearned(fs, "normal_y", normal[1]);
  WriteLearned(fs, "normal_z", normal[2]);
  fs << kEndMarker << kModelFormat;
  return SealModelText(fs.releaseAndGetString());
}

PlaneModel PlaneModel::FromYaml(const std::string& text, const std::string& where) {
  return WithOpenCvErrorsNamed(where, [&] { return ParseModel(text, where); });
}

void PlaneModel::Write(const std::string& path) const { WriteFileAtomically(path, ToYaml()); }

PlaneModel PlaneModel::Read(const std::string& path) { return FromYaml(ReadFile(path), path); }

Eigen::VectorXd WordPlaneLogOdds(const Eigen::VectorXd& plane_counts, const Eigen::VectorXd& non_plane_counts) {
  PDVO_THROW_CHECK(plane_counts.size() == non_plane_counts.size() && plane_counts.minCoeff() >= 0 &&
                       non_plane_counts.minCoeff() >= 0,
                   InvalidArgument, "word log-odds: counts of different sizes or negative");
  const double planes = plane_counts.sum(), non_planes = non_plane_counts.sum();
  PDVO_THROW_CHECK(planes > 0 && non_planes > 0, InvalidArgument,
                   "word log-odds: no salient points on annotated planes or on annotated non-planes");
  const double share = planes / (planes + non_planes);
  const Eigen::ArrayXd plane = plane_counts.array() + kWordPriorCounts * share;
  const Eigen::ArrayXd non_plane = non_plane_counts.array() + kWordPriorCounts * (1 - share);
  return ((plane / non_plane).log() - std::log(share / (1 - share))).matrix();
}

std::string SealModelText(std::string text) {
  if (text.substr(LastLineStart(text)).starts_with(kChecksumPrefix)) text.resize(LastLineStart(text));
  if (!text.empty() && text.back() != '\n') text += '\n';
  const std::string crc = Crc32Hex(text);
  return text.append(kChecksumPrefix).append(crc).append("\n");
}

}  // namespace pdvo
