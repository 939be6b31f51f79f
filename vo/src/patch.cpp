#include "pdvo/vo/patch.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo::vo {

bool SearchOptions::Check() const {
  PDVO_CHECK_OPTION(patch_half >= 1 && search_sigmas > 0 && max_search_radius >= 1);
  PDVO_CHECK_OPTION(min_ncc > -1 && min_ncc < 1 && pixel_sigma > 0);
  return true;
}

bool WarpPatch(const cv::Mat& reference, const Eigen::Matrix3d& h, const Eigen::Vector2d& centre, int half,
               cv::Mat* patch) {
  PDVO_THROW_CHECK(reference.type() == CV_8UC1 && reference.cols >= 2 && reference.rows >= 2, InvalidArgument,
                   "WarpPatch: the reference must be an 8-bit grey image of at least 2x2");
  PDVO_THROW_CHECK(half >= 0, InvalidArgument, "WarpPatch: negative patch size");
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(h);
  if (!lu.isInvertible()) return false;
  const Eigen::Matrix3d back = lu.inverse();
  const int side = 2 * half + 1;
  cv::Mat out(side, side, CV_32F);
  for (int dy = -half; dy <= half; ++dy) {
    for (int dx = -half; dx <= half; ++dx) {
      const Eigen::Vector3d q = back * Eigen::Vector3d(centre.x() + dx, centre.y() + dy, 1);
      if (q.z() <= 0) return false;
      const double x = q.x() / q.z(), y = q.y() / q.z();
      if (!(x >= 0 && y >= 0 && x <= reference.cols - 1 && y <= reference.rows - 1)) return false;
      const int x0 = std::min(static_cast<int>(x), reference.cols - 2),
                y0 = std::min(static_cast<int>(y), reference.rows - 2);
      const double ax = x - x0, ay = y - y0;
      const uchar* r0 = reference.ptr<uchar>(std::max(y0, 0));
      const uchar* r1 = reference.ptr<uchar>(std::min(y0 + 1, reference.rows - 1));
      const int x1 = std::min(x0 + 1, reference.cols - 1);
      out.at<float>(dy + half, dx + half) =
          static_cast<float>((1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x1]));
    }
  }
  *patch = out;
  return true;
}

double Ncc(const cv::Mat& a, const cv::Mat& b) {
  PDVO_THROW_CHECK(a.size() == b.size() && a.channels() == 1 && b.channels() == 1, InvalidArgument,
                   "Ncc: patches of different sizes or with several channels");
  cv::Mat fa, fb;
  a.convertTo(fa, CV_64F);
  b.convertTo(fb, CV_64F);
  fa -= cv::mean(fa)[0];
  fb -= cv::mean(fb)[0];
  const double norms = std::sqrt(fa.dot(fa) * fb.dot(fb));
  return norms > 1e-12 ? fa.dot(fb) / norms : 0.0;
}

}  // namespace pdvo::vo

namespace pdvo::vo {

namespace {

// The zero-mean NCC of a patch with the image patches of a window, by direct sums. The patch is made zero-mean
// once (its correlation with an image patch is then that of both made zero-mean); summed-area tables of the
// window's values and squares give each image patch's mean and variance in O(1). Positions (x, y) are the image
// patches' top-left corners in the window.
class WindowCorrelation {
 public:
  WindowCorrelation(const cv::Mat& image, const cv::Rect& window, const cv::Mat& patch)
      : side_(patch.rows),
        width_(window.width),
        stride_(window.width + 1),
        rows_(window.height - side_ + 1),
        cols_(window.width - side_ + 1),
        patch_(patch.begin<float>(), patch.end<float>()),
        values_(static_cast<size_t>(window.width) * window.height),
        sum_(static_cast<size_t>(stride_) * (window.height + 1), 0.0),
        square_(sum_) {
    const int n = side_ * side_;
    double mean = 0;
    for (float v : patch_) mean += v;
    mean /= n;
    for (float& v : patch_) {
      v = static_cast<float>(v - mean);
      patch_norm2_ += static_cast<double>(v) * v;
    }
    for (int y = 0; y < window.height; ++y) {
      const uchar* row = image.ptr<uchar>(window.y + y) + window.x;
      double line = 0, line_square = 0;
      for (int x = 0; x < window.width; ++x) {
        values_[y * width_ + x] = row[x];
        line += row[x];
        line_square += static_cast<double>(row[x]) * row[x];
        sum_[(y + 1) * stride_ + x + 1] = sum_[y * stride_ + x + 1] + line;
        square_[(y + 1) * stride_ + x + 1] = square_[y * stride_ + x + 1] + line_square;
      }
    }
  }
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  bool flat_patch() const { return !(patch_norm2_ > 1e-9); }

  // The NCCs at positions first .. last - 1 of row y into out[first .. last - 1] (`dots` scratch, cols() long):
  // summed for the whole run at once, which vectorises; each position's sums in the same order whatever the run.
  void Row(int y, int first, int last, std::vector<float>* dots, std::vector<double>* out) const {
    std::fill(dots->begin() + first, dots->begin() + last, 0.0f);
    for (int r = 0; r < side_; ++r) {
      const float* row = values_.data() + (y + r) * width_;
      for (int c = 0; c < side_; ++c) {
        const float q = patch_[r * side_ + c];
        for (int x = first; x < last; ++x) (*dots)[x] += row[x + c] * q;
      }
    }
    for (int x = first; x < last; ++x) (*out)[x] = Normalised((*dots)[x], x, y);
  }

 private:
  double Normalised(float dot, int x, int y) const {
    auto box = [&](const std::vector<double>& t) {
      return t[(y + side_) * stride_ + x + side_] - t[y * stride_ + x + side_] - t[(y + side_) * stride_ + x] +
             t[y * stride_ + x];
    };
    const double s = box(sum_), variance = box(square_) - s * s / (side_ * side_);
    return variance > 1e-9 ? dot / std::sqrt(variance * patch_norm2_) : 0.0;  // a flat image patch: 0
  }

  int side_, width_, stride_, rows_, cols_;
  std::vector<float> patch_;   // zero-mean
  double patch_norm2_ = 0;     // its squared norm
  std::vector<float> values_;  // the window
  std::vector<double> sum_, square_;
};

}  // namespace

bool SearchPatch(const cv::Mat& image, const cv::Mat& patch, const Eigen::Vector2d& predicted,
                 const Eigen::Matrix2d& innovation, const SearchOptions& o, Eigen::Vector2d* found) {
  const int half = o.patch_half, side = 2 * half + 1;
  PDVO_THROW_CHECK(image.type() == CV_8UC1 && patch.type() == CV_32FC1 && patch.rows == side && patch.cols == side,
                   InvalidArgument,
                   "SearchPatch: expected an 8-bit grey image and a " << side << "x" << side << " CV_32F patch");
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(innovation).eigenvalues().maxCoeff();
  // Bounded before the conversion: a huge (or NaN) covariance gives the largest window, not an overflow.
  const double wanted_radius = std::ceil(o.search_sigmas * std::sqrt(largest));
  const int radius = wanted_radius < o.max_search_radius ? static_cast<int>(wanted_radius) : o.max_search_radius;
  if (!(std::abs(predicted.x()) < 1e6 && std::abs(predicted.y()) < 1e6)) return false;
  const cv::Point centre(cvRound(predicted.x()), cvRound(predicted.y()));
  const cv::Rect wanted(centre.x - radius - half, centre.y - radius - half, 2 * (radius + half) + 1,
                        2 * (radius + half) + 1);
  const cv::Rect window = wanted & cv::Rect(0, 0, image.cols, image.rows);
  if (window.width < side || window.height < side) return false;
  const WindowCorrelation ncc(image, window, patch);
  if (ncc.flat_patch()) return false;
  // Scored only where the innovation ellipse reaches (the window is its bounding square): per row of positions,
  // the run of columns inside it (an ellipse is convex).
  const Eigen::Matrix2d information = innovation.inverse();
  const double gate = o.search_sigmas * o.search_sigmas;
  auto inside = [&](int x, int y) {
    const Eigen::Vector2d d(window.x + x + half - predicted.x(), window.y + y + half - predicted.y());
    return !(d.dot(information * d) > gate);  // a NaN covariance: the whole window
  };
  double best = -2;
  cv::Point at(-1, -1);
  std::vector<float> dots(ncc.cols());
  std::vector<double> scores(ncc.cols());
  for (int y = 0; y < ncc.rows(); ++y) {
    int first = 0;
    while (first < ncc.cols() && !inside(first, y)) ++first;
    int last = first;
    while (last < ncc.cols() && inside(last, y)) ++last;
    ncc.Row(y, first, last, &dots, &scores);
    for (int x = first; x < last; ++x) {
      if (scores[x] <= best) continue;
      best = scores[x];
      at = cv::Point(x, y);
    }
  }
  if (best < o.min_ncc) return false;
  // Sub-pixel: a parabola through the peak and its neighbours, per axis.
  auto offset = [](double l, double c, double r) {
    const double curvature = l - 2 * c + r;
    return curvature < 0 ? std::clamp(0.5 * (l - r) / curvature, -0.5, 0.5) : 0.0;
  };
  double dx = 0, dy = 0;
  auto score = [&](int x, int y) {  // a neighbour's, inside the ellipse or not
    ncc.Row(y, x, x + 1, &dots, &scores);
    return scores[x];
  };
  if (at.x > 0 && at.x + 1 < ncc.cols()) dx = offset(score(at.x - 1, at.y), best, score(at.x + 1, at.y));
  if (at.y > 0 && at.y + 1 < ncc.rows()) dy = offset(score(at.x, at.y - 1), best, score(at.x, at.y + 1));
  *found = Eigen::Vector2d(window.x + at.x + half + dx, window.y + at.y + half + dy);
  return true;
}

}  // namespace pdvo::vo
