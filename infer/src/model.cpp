#include "pdvo/infer/model.h"

#include <cmath>
#include <opencv2/core/eigen.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/common/file_io.h"
#include "pdvo/common/options.h"

namespace pdvo {
namespace {

constexpr const char* kEndMarker = "end_of_model";

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

}  // namespace

double RvmFunction::operator()(const Eigen::VectorXd& x) const {
  double sum = -bias;
  for (Eigen::Index i = 0; i < vectors.rows(); ++i) {
    sum += weights[i] * std::exp(-gamma * (vectors.row(i).transpose() - x).squaredNorm());
  }
  return sum;
}

Eigen::VectorXd RvmFunction::Evaluate(const Eigen::MatrixXd& rows) const {
  if (vectors.rows() == 0) return Eigen::VectorXd::Constant(rows.rows(), -bias);
  Eigen::MatrixXd distance = -2.0 * rows * vectors.transpose();
  distance.colwise() += rows.rowwise().squaredNorm();
  distance.rowwise() += vectors.rowwise().squaredNorm().transpose();
  return (-gamma * distance.cwiseMax(0.0)).array().exp().matrix() * weights -
         Eigen::VectorXd::Constant(rows.rows(), bias);
}

bool RecogniserOptions::Check() const {
  PDVO_CHECK_OPTION(working_width == 0 || working_width >= 32);
  PDVO_CHECK_OPTION(features.Check());
  PDVO_CHECK_OPTION(min_points >= 1);
  PDVO_CHECK_OPTION(topic_iterations >= 1);
  PDVO_CHECK_OPTION(vanishing.Check());
  return true;
}

std::string PlaneModel::ToYaml() const {
  // Matrices in base64 (raw bytes: a third of the size of their text, and exactly the same values).
  cv::FileStorage fs(".yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::BASE64);
  fs << "format" << kModelFormat << "version" << kModelVersion;
  fs << "options"
     << "{";
  WriteOptions(fs, options);
  fs << "}";
  fs << "card"
     << "{"
     << "data" << card.data << "images" << card.images << "plane_regions" << card.plane_regions << "non_plane_regions"
     << card.non_plane_regions << "normal_regions" << card.normal_regions << "folds" << card.folds << "cv_accuracy"
     << card.cv_accuracy << "cv_normal_error_deg" << card.cv_normal_error << "seed" << card.seed << "training_options"
     << card.training_options << "pdvo_version" << card.pdvo_version << "git_commit" << card.git_commit << "}";
  gradient_words.Write(fs, "gradient_words");
  colour_words.Write(fs, "colour_words");
  fs << "topics" << ToMat(topics) << "feature_mean" << ToMat(feature_mean) << "feature_scale" << ToMat(feature_scale);
  fs << "classifiers"
     << "[";
  for (const RvmFunction& f : classifiers) WriteRvm(fs, "", f);
  fs << "]";
  WriteRvm(fs, "normal_x", normal[0]);
  WriteRvm(fs, "normal_y", normal[1]);
  WriteRvm(fs, "normal_z", normal[2]);
  fs << kEndMarker << kModelFormat;
  return fs.releaseAndGetString();
}

PlaneModel PlaneModel::FromYaml(const std::string& text, const std::string& where) {
  cv::FileStorage fs;
  try {
    fs.open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const cv::Exception& e) {
    PDVO_THROW(FormatError, where << ": not a readable model (truncated or corrupt YAML)");
  }
  PDVO_THROW_CHECK(fs.isOpened() && fs.root().isMap(), FormatError, where << ": not a readable model");
  PDVO_THROW_CHECK(static_cast<std::string>(fs["format"]) == kModelFormat, FormatError,
                   where << ": not a " << kModelFormat << " file");
  const int version = static_cast<int>(fs["version"]);
  PDVO_THROW_CHECK(version == kModelVersion, FormatError,
                   where << ": model version " << version << ", this build reads version " << kModelVersion
                         << " (retrain with pdvo train)");
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
  m.gradient_words = Vocabulary::Read(fs["gradient_words"], where + ": gradient_words");
  m.colour_words = Vocabulary::Read(fs["colour_words"], where + ": colour_words");
  PDVO_THROW_CHECK(m.gradient_words.dims() == kGradientDims && m.colour_words.dims() == kColourDims, FormatError,
                   where << ": vocabularies of the wrong descriptor size");
  m.topics = ReadMatrix(fs.root(), where, "topics");
  PDVO_THROW_CHECK(m.topics.rows() == m.gradient_words.size() + m.colour_words.size() && (m.topics.array() >= 0).all(),
                   FormatError, where << ": the topic basis does not match the vocabularies");
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
    m.classifiers.push_back(ReadRvm(classifiers[static_cast<int>(i)], what, dims));
  }
  m.normal[0] = ReadRvm(fs["normal_x"], where + ": normal_x", dims);
  m.normal[1] = ReadRvm(fs["normal_y"], where + ": normal_y", dims);
  m.normal[2] = ReadRvm(fs["normal_z"], where + ": normal_z", dims);
  return m;
}

void PlaneModel::Write(const std::string& path) const { WriteFileAtomically(path, ToYaml()); }

PlaneModel PlaneModel::Read(const std::string& path) { return FromYaml(ReadFile(path), path); }

}  // namespace pdvo
