#include "pdvo/infer/spatiogram.h"

#include "pdvo/common/errors.h"

namespace pdvo {

Eigen::VectorXd Spatiogram::ToVector() const {
  const Eigen::Index topics = weights.size();
  Eigen::VectorXd v(6 * topics);
  for (Eigen::Index t = 0; t < topics; ++t) {
    v.segment<6>(6 * t) << weights[t], means[t].x(), means[t].y(), covariances[t](0, 0), covariances[t](0, 1),
        covariances[t](1, 1);
  }
  return v;
}

Spatiogram ComputeSpatiogram(const Eigen::MatrixXd& basis, const std::vector<int>& words,
                             const std::vector<cv::Point2f>& points, const cv::Rect2d& region,
                             const Eigen::VectorXd& topic_weights) {
  const Eigen::Index topics = basis.cols();
  PDVO_THROW_CHECK(words.size() == points.size(), InvalidArgument,
                   "spatiogram: " << words.size() << " words for " << points.size() << " points");
  PDVO_THROW_CHECK(topic_weights.size() == topics, InvalidArgument,
                   "spatiogram: " << topic_weights.size() << " topic weights for " << topics << " topics");
  PDVO_THROW_CHECK(region.width > 0 && region.height > 0, InvalidArgument, "spatiogram: empty region");
  const Eigen::Vector2d centre(region.x + region.width / 2, region.y + region.height / 2);
  const Eigen::Vector2d half(region.width / 2, region.height / 2);
  Spatiogram s;
  s.weights = topic_weights;
  s.means.assign(topics, Eigen::Vector2d::Zero());
  s.covariances.assign(topics, Eigen::Matrix2d::Zero());
  std::vector<double> mass(topics, 0.0);
  std::vector<Eigen::Vector2d> normalised;
  for (size_t i = 0; i < points.size(); ++i) {
    PDVO_THROW_CHECK(words[i] >= 0 && words[i] < basis.rows(), InvalidArgument,
                     "spatiogram: word " << words[i] << " is not in the vocabulary of " << basis.rows());
    normalised.push_back((Eigen::Vector2d(points[i].x, points[i].y) - centre).cwiseQuotient(half));
  }
  // Weighted means, then weighted covariances about them (two passes, for accuracy).
  for (size_t i = 0; i < points.size(); ++i) {
    for (Eigen::Index t = 0; t < topics; ++t) {
      const double w = basis(words[i], t);
      mass[t] += w;
      s.means[t] += w * normalised[i];
    }
  }
  for (Eigen::Index t = 0; t < topics; ++t) {
    if (mass[t] > 0) s.means[t] /= mass[t];
  }
  for (size_t i = 0; i < points.size(); ++i) {
    for (Eigen::Index t = 0; t < topics; ++t) {
      const Eigen::Vector2d d = normalised[i] - s.means[t];
      s.covariances[t] += basis(words[i], t) * d * d.transpose();
    }
  }
  for (Eigen::Index t = 0; t < topics; ++t) {
    if (mass[t] > 0) s.covariances[t] /= mass[t];
  }
  return s;
}

}  // namespace pdvo
