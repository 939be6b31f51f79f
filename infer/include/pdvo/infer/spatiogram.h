// A region's spatiogram (the paper's section III, step 5; spatiograms after Birchfield & Rangarajan 2005): for
// each topic, its weight in the region and the mean and covariance of the positions of the region's points,
// each point weighted by how much its visual word belongs to the topic (the word's entry in the topic basis).
// Positions are normalised to the region's bounding box: its corners map to (-1, -1) and (1, 1).
#pragma once

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <vector>

namespace pdvo {

struct Spatiogram {
  Eigen::VectorXd weights;                   // per topic
  std::vector<Eigen::Vector2d> means;        // per topic, normalised region coordinates; 0 without support
  std::vector<Eigen::Matrix2d> covariances;  // per topic; 0 without support

  // Per topic: weight, mean x, mean y, cov xx, cov xy, cov yy (6 values a topic), for the classifiers.
  Eigen::VectorXd ToVector() const;
};

// `basis` is words x topics (non-negative); `words[i]` is the word of the point at `points[i]` (pixels);
// `topic_weights` are the region's projection onto the topics. Throws InvalidArgument for mismatched sizes, a
// word out of range, or an empty region box.
Spatiogram ComputeSpatiogram(const Eigen::MatrixXd& basis, const std::vector<int>& words,
                             const std::vector<cv::Point2f>& points, const cv::Rect2d& region,
                             const Eigen::VectorXd& topic_weights);

}  // namespace pdvo
