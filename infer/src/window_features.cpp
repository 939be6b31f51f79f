#include "pdvo/infer/window_features.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"
#include "pdvo/infer/topics.h"

namespace pdvo {
namespace {

// Channel layout of a cell: the point count, the word counts (gradient then colour words), per topic its
// membership's moments (m, m x, m y, m x^2, m x y, m y^2), per orientation bin the same, per edge family
// (near horizontal, near vertical) the weighted moments (w, w x, w y, w x^2, w x y, w y^2, w e, w e x, w e y).
constexpr int kMoments = 6;
constexpr int kFamilyMoments = 9;

void AddMoments(double m, double x, double y, double* c) {
  c[0] += m;
  c[1] += m * x;
  c[2] += m * y;
  c[3] += m * x * x;
  c[4] += m * x * y;
  c[5] += m * y * y;
}

// The spatiogram entries (weight, mean, covariance in the box's normalised coordinates) from raw moments.
void MomentsToSpatiogram(double weight, const double* c, const Eigen::Vector2d& centre, const Eigen::Vector2d& half,
                         double* out) {
  out[0] = weight;
  out[1] = out[2] = out[3] = out[4] = out[5] = 0;
  if (c[0] <= 0) return;
  const double mx = c[1] / c[0], my = c[2] / c[0];
  out[1] = (mx - centre.x()) / half.x();
  out[2] = (my - centre.y()) / half.y();
  out[3] = (c[3] / c[0] - mx * mx) / (half.x() * half.x());
  out[4] = (c[4] / c[0] - mx * my) / (half.x() * half.y());
  out[5] = (c[5] / c[0] - my * my) / (half.y() * half.y());
}

}  // namespace

WindowFeatures::WindowFeatures(const ImageWords& words, const PlaneModel& model, int cell)
    : words_(words), model_(model), gram_(model.topics.transpose() * model.topics), cell_(cell) {
  PDVO_THROW_CHECK(cell >= 1 && words.image_size.width >= cell && words.image_size.height >= cell, InvalidArgument,
                   "window features: a cell of " << cell << " px for a " << words.image_size.width << "x"
                                                 << words.image_size.height << " image");
  const int g = model.gradient_words.size(), c = model.colour_words.size();
  const int topics = static_cast<int>(model.topics.cols());
  columns_ = words.image_size.width / cell;
  rows_ = words.image_size.height / cell;
  channels_ = 1 + g + c + kMoments * (topics + kOrientationBins) + 2 * kFamilyMoments;
  const int words_at = 1, topics_at = 1 + g + c, bins_at = topics_at + kMoments * topics;
  const int families_at = bins_at + kMoments * kOrientationBins;
  table_.assign(static_cast<size_t>(rows_ + 1) * (columns_ + 1) * channels_, 0.0);
  auto at = [&](int row, int column) {
    return &table_[(static_cast<size_t>(row) * (columns_ + 1) + column) * channels_];
  };
  for (size_t i = 0; i < words.size(); ++i) {
    const cv::Point2f& p = words.points[i];
    const cv::Point pixel = NearestPixel(p);
    const int px = pixel.x, py = pixel.y;
    const int column = px / cell_, row = py / cell_;
    if (px < 0 || py < 0 || column >= columns_ || row >= rows_) continue;  // in no aligned window
    const int gw = words.gradient[i], cw = words.colour[i];
    PDVO_THROW_CHECK(gw >= 0 && gw < g && cw >= 0 && cw < c, InvalidArgument,
                     "window features: a word out of the vocabulary's range");
    double* out = at(row + 1, column + 1);
    const double x = p.x, y = p.y;
    out[0] += 1;
    out[words_at + gw] += 1;
    out[words_at + g + cw] += 1;
    for (int t = 0; t < topics; ++t) {
      AddMoments(model.topics(gw, t) + model.topics(g + cw, t), x, y, out + topics_at + kMoments * t);
    }
    const int bin = std::min(kOrientationBins - 1, static_cast<int>(words.angle[i] / CV_PI * kOrientationBins));
    AddMoments(1, x, y, out + bins_at + kMoments * bin);
    // The edge across the gradient, folded about its family's axis (as LayoutFeature does).
    const double gradient = words.angle[i];
    const int family = gradient > CV_PI / 4 && gradient <= 3 * CV_PI / 4 ? 0 : 1;
    double edge = family == 0 ? gradient - CV_PI / 2 : gradient;
    if (edge > CV_PI / 2) edge -= CV_PI;
    const double w = static_cast<double>(words.coherence[i]) * words.coherence[i];
    double* f = out + families_at + kFamilyMoments * family;
    AddMoments(w, x, y, f);
    f[6] += w * edge;
    f[7] += w * edge * x;
    f[8] += w * edge * y;
  }
  // The topics' channels per cell, then the summed-area over the cells: each entry becomes the sum of the cells
  // above and to the left of it.
  const int topic_channels = kMoments * topics;
  topic_cells_.assign(static_cast<size_t>(rows_) * columns_ * topic_channels, 0.0);
  for (int row = 0; row < rows_; ++row) {
    for (int column = 0; column < columns_; ++column) {
      const double* from = at(row + 1, column + 1) + topics_at;
      std::copy(from, from + topic_channels,
                &topic_cells_[(static_cast<size_t>(row) * columns_ + column) * topic_channels]);
    }
  }
  for (int row = 1; row <= rows_; ++row) {
    for (int column = 1; column <= columns_; ++column) {
      double* out = at(row, column);
      const double *up = at(row - 1, column), *left = at(row, column - 1), *corner = at(row - 1, column - 1);
      for (int k = 0; k < channels_; ++k) out[k] += up[k] + left[k] - corner[k];
    }
  }
  // Edge pixels: as EdgeStructure counts them.
  const EdgePlanes& e = words.edges;
  if (!e.normals.empty()) {
    const cv::Size size = e.normals.size();
    cv::Mat channels(size, CV_64FC3, cv::Scalar::all(0));
    const Eigen::Vector3f up = e.up.cast<float>();
    const float vertical_sin = static_cast<float>(std::sin(model.options.vanishing.vertical_band_deg * CV_PI / 180));
    for (int y = 0; y < size.height; ++y) {
      const cv::Vec3f* normal = e.normals.ptr<cv::Vec3f>(y);
      const float* strength = e.strength.ptr<float>(y);
      cv::Vec3d* out = channels.ptr<cv::Vec3d>(y);
      for (int x = 0; x < size.width; ++x) {
        if (strength[x] <= 0) continue;
        const Eigen::Vector3f m(normal[x][0], normal[x][1], normal[x][2]);
        out[x] = cv::Vec3d(1, strength[x], std::abs(m.dot(up)) < vertical_sin ? strength[x] : 0.0);
      }
    }
    cv::integral(channels, edge_table_, CV_64F);
  }
}

cv::Rect WindowFeatures::Cells(const cv::Rect& box) const {
  PDVO_THROW_CHECK(box.width > 0 && box.height > 0 && box.x % cell_ == 0 && box.y % cell_ == 0 &&
                       box.width % cell_ == 0 && box.height % cell_ == 0 && box.x >= 0 && box.y >= 0 &&
                       (box.x + box.width) / cell_ <= columns_ && (box.y + box.height) / cell_ <= rows_,
                   InvalidArgument,
                   "window features: the window " << box << " is not on the " << cell_ << " px grid of the image");
  return {box.x / cell_, box.y / cell_, box.width / cell_, box.height / cell_};
}

const double* WindowFeatures::Corner(int row, int column) const {
  return &table_[(static_cast<size_t>(row) * (columns_ + 1) + column) * channels_];
}

Eigen::VectorXd WindowFeatures::Sum(const cv::Rect& box) const {
  const cv::Rect cells = Cells(box);
  const int x0 = cells.x, y0 = cells.y, x1 = cells.x + cells.width, y1 = cells.y + cells.height;
  auto at = [&](int row, int column) { return Eigen::Map<const Eigen::VectorXd>(Corner(row, column), channels_); };
  Eigen::VectorXd sum = at(y1, x1) - at(y0, x1) - at(y1, x0) + at(y0, x0);
  const int g = model_.gradient_words.size(), c = model_.colour_words.size();
  const int topic_channels = kMoments * static_cast<int>(model_.topics.cols());
  Eigen::Ref<Eigen::VectorXd> topics = sum.segment(1 + g + c, topic_channels);
  topics.setZero();
  for (int row = y0; row < y1; ++row) {
    for (int column = x0; column < x1; ++column) {
      topics += Eigen::Map<const Eigen::VectorXd>(
          &topic_cells_[(static_cast<size_t>(row) * columns_ + column) * topic_channels], topic_channels);
    }
  }
  return sum;
}

int WindowFeatures::Points(const cv::Rect& box) const {  // the count channel (0) alone
  const cv::Rect c = Cells(box);
  const int x1 = c.x + c.width, y1 = c.y + c.height;
  return static_cast<int>(std::lround(*Corner(y1, x1) - *Corner(c.y, x1) - *Corner(y1, c.x) + *Corner(c.y, c.x)));
}

Eigen::VectorXd WindowFeatures::Feature(const cv::Rect& box) const { return Features({box}).row(0).transpose(); }

Eigen::MatrixXd WindowFeatures::Features(const std::vector<cv::Rect>& boxes) const {
  const int words = model_.gradient_words.size() + model_.colour_words.size();
  std::vector<Eigen::VectorXd> sums;
  Eigen::MatrixXd histograms(words, static_cast<Eigen::Index>(boxes.size()));  // as CollectRegionWords
  for (size_t k = 0; k < boxes.size(); ++k) {
    sums.push_back(Sum(boxes[k]));
    const double n = sums.back()[0];
    histograms.col(static_cast<Eigen::Index>(k)) = sums.back().segment(1, words) / (n > 0 ? 2.0 * n : 1.0);
  }
  // The topics of all windows at once: the projection's iterations as matrix products.
  const Eigen::MatrixXd weights = ProjectOntoTopics(model_.topics, gram_, histograms, model_.options.topic_iterations);
  Eigen::MatrixXd features(static_cast<Eigen::Index>(boxes.size()), RegionFeatureDims(static_cast<int>(gram_.cols())));
  for (size_t k = 0; k < boxes.size(); ++k) {
    const Eigen::Index row = static_cast<Eigen::Index>(k);
    features.row(row) = Complete(boxes[k], sums[k], weights.col(row)).transpose();
  }
  return features;
}

Eigen::VectorXd WindowFeatures::Complete(const cv::Rect& box, const Eigen::VectorXd& s,
                                         const Eigen::VectorXd& weights) const {
  const int g = model_.gradient_words.size(), c = model_.colour_words.size();
  const int topics = static_cast<int>(model_.topics.cols());
  const int topics_at = 1 + g + c, bins_at = topics_at + kMoments * topics;
  const int families_at = bins_at + kMoments * kOrientationBins;
  const double n = s[0];
  // As CollectRegionWords: the box in pixel-edge coordinates.
  const cv::Rect2d edges(box.x - 0.5, box.y - 0.5, box.width, box.height);
  const Eigen::Vector2d centre(edges.x + edges.width / 2, edges.y + edges.height / 2);
  const Eigen::Vector2d half(edges.width / 2, edges.height / 2);
  Eigen::VectorXd feature(RegionFeatureDims(topics));
  for (int t = 0; t < topics; ++t) {
    MomentsToSpatiogram(weights[t], s.data() + topics_at + kMoments * t, centre, half, feature.data() + kMoments * t);
  }
  double* by_orientation = feature.data() + kMoments * topics;
  for (int b = 0; b < kOrientationBins; ++b) {
    const double* m = s.data() + bins_at + kMoments * b;
    MomentsToSpatiogram(n > 0 ? m[0] / n : 0.0, m, centre, half, by_orientation + kMoments * b);
  }
  // The layout, as LayoutFeature: per family the weighted least squares of the edge angle on (1, dx, dy), dx and
  // dy from the box's centre in image widths.
  const double w = words_.image_size.width;
  const Eigen::Vector2d image_centre(words_.image_size.width / 2.0, words_.image_size.height / 2.0);
  Eigen::VectorXd layout(kLayoutDims);
  layout.head<4>() << (centre - image_centre) / w, edges.width / w, edges.height / w;
  constexpr double kRidge = 1e-4;  // as LayoutFeature's
  double mass[2];
  for (int f = 0; f < 2; ++f) {
    const double* m = s.data() + families_at + kFamilyMoments * f;
    const double cx = centre.x(), cy = centre.y();
    const double sx = (m[1] - cx * m[0]) / w, sy = (m[2] - cy * m[0]) / w;
    const double sxx = (m[3] - 2 * cx * m[1] + cx * cx * m[0]) / (w * w);
    const double sxy = (m[4] - cx * m[2] - cy * m[1] + cx * cy * m[0]) / (w * w);
    const double syy = (m[5] - 2 * cy * m[2] + cy * cy * m[0]) / (w * w);
    Eigen::Matrix3d a;
    a << m[0], sx, sy, sx, sxx + kRidge, sxy, sy, sxy, syy + kRidge;
    const Eigen::Vector3d moment(m[6], (m[7] - cx * m[6]) / w, (m[8] - cy * m[6]) / w);
    mass[f] = m[0];
    layout.segment<3>(4 + 3 * f) = m[0] > 0 ? Eigen::Vector3d(a.ldlt().solve(moment)) : Eigen::Vector3d::Zero();
  }
  layout[10] = mass[0] + mass[1] > 0 ? mass[0] / (mass[0] + mass[1]) : 0.5;
  // The edge structure, as EdgeStructure: the share of the box's pixels on edges, the vertical share of strength.
  layout[11] = layout[12] = 0;
  if (!edge_table_.empty()) {
    auto corner = [&](int x, int y) { return edge_table_.at<cv::Vec3d>(y, x); };
    const cv::Vec3d e = corner(box.x + box.width, box.y + box.height) - corner(box.x, box.y + box.height) -
                        corner(box.x + box.width, box.y) + corner(box.x, box.y);
    layout[11] = e[0] / box.area();
    layout[12] = e[1] > 0 ? e[2] / e[1] : 0.0;
  }
  feature.tail(kLayoutDims) = layout;
  return feature;
}

}  // namespace pdvo
