// A visual vocabulary (the paper's section III, step 3): descriptors clustered by k-means into words; new
// descriptors are quantised to their nearest word (exactly, by one matrix product per block of descriptors: at 300
// words of 128-D that is ~10 times faster than a FLANN kd-tree visiting 64 leaves, which was approximate).
// Stored in cv::FileStorage.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
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

  // The nearest word of each row (CV_32F, dims() columns; ties to the lower index, up to float rounding).
  std::vector<int> Quantise(const cv::Mat& descriptors) const;

  int size() const { return centres_.rows; }
  int dims() const { return centres_.cols; }
  const cv::Mat& centres() const { return centres_; }

  void Write(cv::FileStorage& fs, const std::string& name) const;
  // Throws FormatError naming `where` if the node is missing or malformed.
  static Vocabulary Read(const cv::FileNode& node, const std::string& where);

 private:
  cv::Mat centres_;
  std::vector<float> centre_norms_;  // squared
};

}  // namespace pdvo
