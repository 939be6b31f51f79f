#include "pdvo/infer/detection_drawing.h"

#include <opencv2/imgproc.hpp>

#include "pdvo/annotations/raster.h"

namespace pdvo {
namespace {

// A panel at the working size with a title.
cv::Mat Titled(cv::Mat panel, const char* title) {
  cv::rectangle(panel, cv::Rect(0, 0, panel.cols, 16), cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(panel, title, cv::Point(4, 12), cv::FONT_HERSHEY_PLAIN, 0.9, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return panel;
}

}  // namespace

cv::Mat DrawDetectionStages(const cv::Mat& image, const Detections& d, const Annotation& a) {
  cv::Mat work;
  cv::resize(image, work, d.image_size, 0, 0, cv::INTER_AREA);
  if (work.channels() == 1) cv::cvtColor(work, work, cv::COLOR_GRAY2BGR);
  cv::Mat sum(d.image_size, CV_32F, cv::Scalar(0)), count(d.image_size, CV_32F, cv::Scalar(0));
  for (const DetectedWindow& w : d.windows) {
    sum(w.box) += w.plane_probability;
    count(w.box) += 1;
  }
  cv::Mat probability = sum / cv::max(count, 1.0f), heat, windows;
  probability.convertTo(heat, CV_8U, 255);
  cv::applyColorMap(heat, heat, cv::COLORMAP_JET);
  cv::addWeighted(work, 0.4, heat, 0.6, 0, windows);
  cv::Mat planarity = work * 0.5, normals = work * 0.5, labels = work * 0.5;
  for (size_t i = 0; i < d.points.size(); ++i) {
    const cv::Point p(cvRound(d.points[i].x), cvRound(d.points[i].y));
    const double q = d.planarity[i];
    cv::circle(planarity, p, 2, cv::Scalar(0, 255 * q, 255 * (1 - q)), cv::FILLED);
    if (d.normals[i].squaredNorm() > 0) cv::circle(normals, p, 2, NormalColour(d.normals[i]), cv::FILLED);
    // Orientation labels: distinct colours (BGR); non-planar points white.
    static const cv::Scalar kPalette[] = {{255, 128, 0}, {0, 200, 255}, {255, 0, 200}, {0, 255, 0},
                                          {0, 80, 255},  {255, 255, 0}, {128, 0, 255}, {0, 160, 120}};
    const int l = d.orientation[i];
    cv::circle(labels, p, 2, l < 0 ? cv::Scalar(255, 255, 255) : kPalette[l % 8], cv::FILLED);
  }
  OverlayOptions overlay;
  overlay.legend = false;
  cv::Mat final_planes;
  cv::resize(DrawOverlay(image.channels() == 1 ? work : image, a, overlay), final_planes, d.image_size, 0, 0,
             cv::INTER_AREA);
  cv::Mat top, bottom, out;
  cv::hconcat(std::vector<cv::Mat>{Titled(work.clone(), "image"), Titled(windows, "windows: plane probability"),
                                   Titled(planarity, "points: planarity")},
              top);
  cv::hconcat(std::vector<cv::Mat>{Titled(normals, "points: normal"), Titled(labels, "MRF 1 and 2"),
                                   Titled(final_planes, "planes")},
              bottom);
  cv::vconcat(top, bottom, out);
  return out;
}

}  // namespace pdvo
