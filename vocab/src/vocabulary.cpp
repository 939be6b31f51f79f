#include "pdvo/vocab/vocabulary.h"

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <random>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {

// Index of the row of `centres` nearest to `x`, by brute force.
int Nearest(const cv::Mat& centres, const float* x, float* distance) {
  int best = 0;
  float best_d = std::numeric_limits<float>::max();
  for (int c = 0; c < centres.rows; ++c) {
    const float* y = centres.ptr<float>(c);
    float d = 0;
    for (int k = 0; k < centres.cols; ++k) d += (x[k] - y[k]) * (x[k] - y[k]);
    if (d < best_d) best_d = d, best = c;
  }
  *distance = best_d;
  return best;
}

}  // namespace

Vocabulary::Vocabulary(cv::Mat centres) : centres_(std::move(centres)) {
  PDVO_THROW_CHECK(centres_.type() == CV_32F && centres_.rows >= 1, InvalidArgument,
                   "vocabulary: centres must be a non-empty CV_32F matrix");
  if (!centres_.isContinuous()) centres_ = centres_.clone();
  centre_norms_.resize(centres_.rows);
  for (int c = 0; c < centres_.rows; ++c)
    centre_norms_[c] = static_cast<float>(cv::norm(centres_.row(c), cv::NORM_L2SQR));
}

Vocabulary Vocabulary::Build(const cv::Mat& data, int words, uint64_t seed, int iterations) {
  PDVO_THROW_CHECK(data.type() == CV_32F && words >= 1 && data.rows >= words, InvalidArgument,
                   "vocabulary: " << words << " words need at least as many CV_32F descriptors, got " << data.rows);
  std::mt19937_64 rng(seed);
  // k-means++ seeding: each next centre drawn with probability proportional to its squared distance.
  cv::Mat centres(words, data.cols, CV_32F);
  data.row(static_cast<int>(std::uniform_int_distribution<int>(0, data.rows - 1)(rng))).copyTo(centres.row(0));
  std::vector<float> d2(data.rows, std::numeric_limits<float>::max());
  for (int c = 1; c < words; ++c) {
    double total = 0;
    for (int i = 0; i < data.rows; ++i) {
      float d = 0;
      Nearest(centres.rowRange(c - 1, c), data.ptr<float>(i), &d);
      d2[i] = std::min(d2[i], d);
      total += d2[i];
    }
    double pick = std::uniform_real_distribution<double>(0, total)(rng);
    int chosen = data.rows - 1;
    for (int i = 0; i < data.rows; ++i) {
      pick -= d2[i];
      if (pick <= 0) {
        chosen = i;
        break;
      }
    }
    data.row(chosen).copyTo(centres.row(c));
  }
  // Lloyd iterations; an emptied word keeps its centre.
  std::vector<int> label(data.rows, -1);
  for (int it = 0; it < iterations; ++it) {
    bool changed = false;
    for (int i = 0; i < data.rows; ++i) {
      float d = 0;
      const int l = Nearest(centres, data.ptr<float>(i), &d);
      changed = changed || l != label[i];
      label[i] = l;
    }
    if (!changed) break;
    cv::Mat sums(words, data.cols, CV_64F, cv::Scalar(0));
    std::vector<int> counts(words, 0);
    for (int i = 0; i < data.rows; ++i) {
      cv::Mat row;
      data.row(i).convertTo(row, CV_64F);
      sums.row(label[i]) += row;
      ++counts[label[i]];
    }
    for (int c = 0; c < words; ++c) {
      if (counts[c] > 0) cv::Mat(sums.row(c) / counts[c]).convertTo(centres.row(c), CV_32F);
    }
  }
  return Vocabulary(centres);
}

std::vector<int> Vocabulary::Quantise(const cv::Mat& descriptors) const {
  PDVO_THROW_CHECK(!centres_.empty(), InvalidArgument, "vocabulary: empty");
  if (descriptors.rows == 0) return {};
  PDVO_THROW_CHECK(descriptors.type() == CV_32F && descriptors.cols == dims(), InvalidArgument,
                   "vocabulary: descriptors are " << descriptors.cols << "-D, the words " << dims() << "-D");
  using RowMajor = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const cv::Mat x_mat = descriptors.isContinuous() ? descriptors : descriptors.clone();
  const Eigen::Map<const RowMajor> x(x_mat.ptr<float>(), x_mat.rows, x_mat.cols);
  const Eigen::Map<const RowMajor> centres(centres_.ptr<float>(), centres_.rows, centres_.cols);
  const Eigen::Map<const Eigen::RowVectorXf> norms(centre_norms_.data(),
                                                   static_cast<Eigen::Index>(centre_norms_.size()));
  // |x - c|^2 = |x|^2 - 2 x.c + |c|^2, of which |x|^2 is the same for every word: one matrix product per block.
  constexpr Eigen::Index kBlock = 256;
  std::vector<int> words(static_cast<size_t>(x.rows()));
  Eigen::MatrixXf cost;
  for (Eigen::Index first = 0; first < x.rows(); first += kBlock) {
    const Eigen::Index n = std::min(kBlock, x.rows() - first);
    cost.noalias() = x.middleRows(first, n) * centres.transpose();
    cost = (-2 * cost).rowwise() + norms;
    for (Eigen::Index i = 0; i < n; ++i) {
      Eigen::Index word = 0;
      cost.row(i).minCoeff(&word);
      words[static_cast<size_t>(first + i)] = static_cast<int>(word);
    }
  }
  return words;
}

void Vocabulary::Write(cv::FileStorage& fs, const std::string& name) const {
  fs << name << "{"
     << "words" << size() << "dims" << dims();
  fs.writeComment("word centres, one per row");
  fs << "centres" << centres_ << "}";
}

Vocabulary Vocabulary::Read(const cv::FileNode& node, const std::string& where) {
  PDVO_THROW_CHECK(node.isMap(), FormatError, where << ": missing vocabulary");
  cv::Mat centres;
  node["centres"] >> centres;
  PDVO_THROW_CHECK(!centres.empty() && centres.type() == CV_32F && centres.rows == static_cast<int>(node["words"]) &&
                       centres.cols == static_cast<int>(node["dims"]),
                   FormatError, where << ": malformed vocabulary (centres do not match words x dims)");
  return Vocabulary(centres);
}

}  // namespace pdvo
