#include "pdvo/vo/patch.h"

#include <Eigen/LU>
#include <cmath>

#include "pdvo/common/errors.h"

namespace pdvo::vo {

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
      const int x0 = std::min(static_cast<int>(x), reference.cols - 2), y0 = std::min(static_cast<int>(y), reference.rows - 2);
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
