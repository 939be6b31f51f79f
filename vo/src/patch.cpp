#include "pdvo/vo/patch.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

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

bool SearchPatch(const cv::Mat& image, const cv::Mat& patch, const Eigen::Vector2d& predicted,
                 const Eigen::Matrix2d& innovation, const SearchOptions& o, Eigen::Vector2d* found) {
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(innovation).eigenvalues().maxCoeff();
  // Bounded before the conversion: a huge (or NaN) covariance gives the largest window, not an overflow.
  const double wanted_radius = std::ceil(o.search_sigmas * std::sqrt(largest));
  const int radius = wanted_radius < o.max_search_radius ? static_cast<int>(wanted_radius) : o.max_search_radius;
  const int half = o.patch_half;
  if (!(std::abs(predicted.x()) < 1e6 && std::abs(predicted.y()) < 1e6)) return false;
  const cv::Point centre(cvRound(predicted.x()), cvRound(predicted.y()));
  const cv::Rect wanted(centre.x - radius - half, centre.y - radius - half, 2 * (radius + half) + 1,
                        2 * (radius + half) + 1);
  const cv::Rect window = wanted & cv::Rect(0, 0, image.cols, image.rows);
  if (window.width < patch.cols || window.height < patch.rows) return false;
  cv::Mat region, score;
  image(window).convertTo(region, CV_32F);
  cv::matchTemplate(region, patch, score, cv::TM_CCOEFF_NORMED);
  const Eigen::Matrix2d information = innovation.inverse();
  const double gate = o.search_sigmas * o.search_sigmas;
  double best = -2;
  cv::Point at(-1, -1);
  for (int y = 0; y < score.rows; ++y) {
    for (int x = 0; x < score.cols; ++x) {
      const float v = score.at<float>(y, x);
      if (!std::isfinite(v) || v <= best) continue;
      const Eigen::Vector2d d(window.x + x + half - predicted.x(), window.y + y + half - predicted.y());
      if (d.dot(information * d) > gate) continue;
      best = v;
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
  if (at.x > 0 && at.x + 1 < score.cols) {
    dx = offset(score.at<float>(at.y, at.x - 1), best, score.at<float>(at.y, at.x + 1));
  }
  if (at.y > 0 && at.y + 1 < score.rows) {
    dy = offset(score.at<float>(at.y - 1, at.x), best, score.at<float>(at.y + 1, at.x));
  }
  *found = Eigen::Vector2d(window.x + at.x + half + dx, window.y + at.y + half + dy);
  return true;
}

}  // namespace pdvo::vo
