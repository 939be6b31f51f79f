// A visual vocabulary (the paper's section III, step 3): descriptors clustered by k-means into words; new
// descriptors are quantised to their nearest word with a FLANN kd-tree. Stored in cv::FileStorage.
#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>
#include <string>
#include <vector>

namespace pdvo {

class Vocabulary {
 public:
  Vocabulary() = default;
  // k-means++ then Lloyd iterations on the rows of `descriptors` (CV_32F). The same seed gives the same words.
  // Throws InvalidArgument if there are fewer rows than words.
  static Vocabulary Build(const cv::Mat& descriptors, int words, uint64_t seed, int iterations = 30);
  // From given word centres (rows, CV_32F).
  explicit Vocabulary(cv::Mat centres);

  // The nearest word of each row (FLANN kd-tree with `checks` leaves visited: approximate; at 64, 98% of real
  // gradient descriptors get their exact nearest word, see the test).
  std::vector<int> Quantise(const cv::Mat& descriptors, int checks = 64) const;

  int size() const { return centres_.rows; }
  int dims() const { return centres_.cols; }
  const cv::Mat& centres() const { return centres_; }

  void Write(cv::FileStorage& fs, const std::string& name) const;
  // Throws FormatError naming `where` if the node is missing or malformed.
  static Vocabulary Read(const cv::FileNode& node, const std::string& where);

 private:
  cv::Mat centres_;
  std::shared_ptr<cv::flann::Index> index_;  // shared: the index is immutable once built
};

}  // namespace pdvo
