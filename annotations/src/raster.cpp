#include "pdvo/annotations/raster.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pdvo/common/errors.h"

namespace pdvo {
namespace {
constexpr int kShift = 4;  // fixed-point bits for sub-pixel polygon filling

std::vector<cv::Point> ScaledPolygon(const AnnotationShape& shape, const Annotation& a, cv::Size size) {
  const double sx = static_cast<double>(size.width) / a.image_width;
  const double sy = static_cast<double>(size.height) / a.image_height;
  std::vector<cv::Point> out;
  out.reserve(shape.points.size());
  // Fixed point with kShift fraction bits, bounded before the conversion (10^7 px, 600 times the largest image
  // side): beyond it only the slopes of edges to far points change.
  constexpr double bound = 1e7;
  const auto fixed = [&](double v) {
    return static_cast<int>(std::lround(std::clamp(v, -bound, bound) * (1 << kShift)));
  };
  for (const auto& p : shape.points) out.emplace_back(fixed((p.x() + 0.5) * sx - 0.5), fixed((p.y() + 0.5) * sy - 0.5));
  return out;
}

cv::Size SizeOr(const Annotation& a, cv::Size size) {
  if (size.empty()) size = cv::Size(a.image_width, a.image_height);
  PDVO_THROW_CHECK(size.width > 0 && size.height > 0 && a.image_width > 0 && a.image_height > 0, InvalidArgument,
                   "rasterise: image size must be positive");
  return size;
}

cv::Rect BoundingBox(const AnnotationShape& s) {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& p : s.points) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  // Bounded before the conversion (points far outside any image are clipped by the caller anyway).
  const auto pixel = [](double v) { return static_cast<int>(std::clamp(v, -1e9, 1e9)); };
  return cv::Rect(cv::Point(pixel(std::floor(x0)), pixel(std::floor(y0))),
                  cv::Point(pixel(std::ceil(x1)) + 1, pixel(std::ceil(y1)) + 1));
}
}  // namespace

cv::Mat RasteriseShape(const AnnotationShape& shape, const Annotation& a, cv::Size size) {
  size = SizeOr(a, size);
  cv::Mat mask(size, CV_8U, cv::Scalar(0));
  if (shape.points.size() >= 3) {
    const std::vector<std::vector<cv::Point>> polys = {ScaledPolygon(shape, a, size)};
    cv::fillPoly(mask, polys, cv::Scalar(255), cv::LINE_8, kShift);
  }
  return mask;
}

AnnotationMasks Rasterise(const Annotation& a, cv::Size size) {
  size = SizeOr(a, size);
  AnnotationMasks m{cv::Mat(size, CV_8U, cv::Scalar(kMaskUnknown)), cv::Mat(size, CV_32S, cv::Scalar(-1)),
                    cv::Mat(size, CV_32FC3, cv::Scalar(0, 0, 0))};
  for (size_t i = 0; i < a.shapes.size(); ++i) {
    const AnnotationShape& s = a.shapes[i];
    if ((!s.IsPlane() && !s.IsNonPlane()) || s.points.size() < 3) continue;
    const std::vector<std::vector<cv::Point>> polys = {ScaledPolygon(s, a, size)};
    const cv::Rect box = cv::boundingRect(polys[0]);
    const cv::Rect roi =
        cv::Rect(box.x >> kShift, box.y >> kShift, (box.width >> kShift) + 2, (box.height >> kShift) + 2) &
        cv::Rect(0, 0, size.width, size.height);
    if (roi.empty()) continue;
    cv::Mat mask(roi.size(), CV_8U, cv::Scalar(0));
    // The offset is in the same fixed-point units as the points.
    cv::fillPoly(mask, polys, cv::Scalar(255), cv::LINE_8, kShift, cv::Point(-roi.x << kShift, -roi.y << kShift));
    m.label(roi).setTo(s.IsPlane() ? kMaskPlane : kMaskNonPlane, mask);
    m.shape_index(roi).setTo(static_cast<int>(i), mask);
    cv::Vec3f n(0, 0, 0);
    if (s.IsPlane() && s.normal && s.normal->allFinite() && s.normal->norm() > 0) {
      const Eigen::Vector3d u = s.normal->normalized();
      n = cv::Vec3f(static_cast<float>(u.x()), static_cast<float>(u.y()), static_cast<float>(u.z()));
    }
    m.normal(roi).setTo(n, mask);
  }
  return m;
}

std::vector<std::pair<int, int>> FindLabelConflicts(const Annotation& a) {
  std::vector<std::pair<int, int>> conflicts;
  const cv::Rect image(0, 0, a.image_width, a.image_height);
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  // Each shape's interior, once: its mask inside its bounding box, eroded so that a shared edge does not count.
  struct Interior {
    cv::Rect box;
    cv::Mat mask;
  };
  std::vector<Interior> interiors(a.shapes.size());
  auto interior = [&](size_t i) -> const Interior& {
    Interior& in = interiors[i];
    if (in.mask.empty()) {
      in.box = BoundingBox(a.shapes[i]) & image;
      if (in.box.area() > 0) cv::erode(RasteriseShape(a.shapes[i], a)(in.box), in.mask, kernel);
    }
    return in;
  };
  for (size_t i = 0; i < a.shapes.size(); ++i) {
    if (!a.shapes[i].IsPlane() || a.shapes[i].points.size() < 3) continue;
    for (size_t j = 0; j < a.shapes.size(); ++j) {
      if (!a.shapes[j].IsNonPlane() || a.shapes[j].points.size() < 3) continue;
      const cv::Rect common = BoundingBox(a.shapes[i]) & BoundingBox(a.shapes[j]) & image;
      if (common.area() == 0) continue;
      const Interior& pi = interior(i);
      const Interior& pj = interior(j);
      const cv::Mat overlap = pi.mask(common - pi.box.tl()) & pj.mask(common - pj.box.tl());
      if (cv::countNonZero(overlap) > 0) conflicts.emplace_back(static_cast<int>(i), static_cast<int>(j));
    }
  }
  return conflicts;
}

cv::Scalar NormalColour(const Eigen::Vector3d& n) {
  auto c = [](double v) { return std::clamp(127.5 * (v + 1.0), 0.0, 255.0); };
  return cv::Scalar(c(n.z()), c(n.y()), c(n.x()));
}

namespace {
void DrawLegend(cv::Mat& panel, double scale) {
  const int w = panel.cols;
  const double font = 0.45 * scale;
  const int line = static_cast<int>(std::lround(18 * scale));
  int y = line;
  auto text = [&](const std::string& s, int x, int yy, cv::Scalar colour = cv::Scalar(230, 230, 230)) {
    cv::putText(panel, s, cv::Point(x, yy), cv::FONT_HERSHEY_SIMPLEX, font, colour, 1, cv::LINE_AA);
  };
  text("plane: tinted by", 8, y);
  y += line;
  text("its normal", 8, y);
  y += line + line / 2;
  // A disc of the normals facing the camera: the centre faces it straight on.
  const int r = std::min(w / 2 - 12, static_cast<int>(60 * scale));
  const cv::Point c(w / 2, y + r + 4);
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const double x = static_cast<double>(dx) / r, yy = static_cast<double>(dy) / r;
      if (x * x + yy * yy > 1) continue;
      // On the rim 1 - x*x - yy*yy may round below 0 (and its root be NaN).
      const cv::Scalar col = NormalColour(Eigen::Vector3d(x, yy, -std::sqrt(std::max(0.0, 1 - x * x - yy * yy))));
      panel.at<cv::Vec3b>(c.y + dy, c.x + dx) =
          cv::Vec3b(static_cast<uchar>(col[0]), static_cast<uchar>(col[1]), static_cast<uchar>(col[2]));
    }
  }
  // Each point of the disc is the colour of a plane facing that way: left, right, up, down.
  const cv::Scalar grey(200, 200, 200);
  text("L", c.x - r - static_cast<int>(12 * scale), c.y + 4, grey);
  text("R", c.x + r + static_cast<int>(3 * scale), c.y + 4, grey);
  text("up", c.x - static_cast<int>(8 * scale), c.y - r - 2, grey);
  text("down", c.x - static_cast<int>(16 * scale), c.y + r + line, grey);
  y = c.y + r + 2 * line;
  text("(the way a plane", 8, y);
  y += line;
  text(" faces; centre:", 8, y);
  y += line;
  text(" at the camera)", 8, y);
  y += line + line / 2;
  cv::Rect hatch(8, y - line / 2 - 4, line, line);
  cv::rectangle(panel, hatch, cv::Scalar(60, 60, 200), cv::FILLED);
  for (int k = -line; k < line; k += 5) {
    cv::line(panel, hatch.tl() + cv::Point(k, 0), hatch.tl() + cv::Point(k + line, line), cv::Scalar(20, 20, 20));
  }
  text("non-plane", 16 + line, y + 2);
  y += line + line / 2;
  cv::rectangle(panel, cv::Rect(8, y - line / 2 - 4, line, line), cv::Scalar(120, 120, 120), 1);
  text("unknown: untinted", 16 + line, y + 2);
}
}  // namespace

cv::Mat DrawOverlay(const cv::Mat& image_in, const Annotation& a, const OverlayOptions& options) {
  PDVO_THROW_CHECK(!image_in.empty(), InvalidArgument, "overlay: empty image");
  PDVO_THROW_CHECK(image_in.cols == a.image_width && image_in.rows == a.image_height, InvalidArgument,
                   "overlay: the image is " << image_in.cols << "x" << image_in.rows << " but the annotation says "
                                            << a.image_width << "x" << a.image_height);
  cv::Mat image;
  if (image_in.channels() == 1) {
    cv::cvtColor(image_in, image, cv::COLOR_GRAY2BGR);
  } else {
    image = image_in.clone();
  }
  const double scale = image.cols > options.max_width ? static_cast<double>(options.max_width) / image.cols : 1.0;
  if (scale < 1.0) cv::resize(image, image, cv::Size(), scale, scale, cv::INTER_AREA);
  const cv::Size size = image.size();
  const double s = std::max(1.0, size.width / 640.0);  // line widths and fonts

  const AnnotationMasks masks = Rasterise(a, size);
  cv::Mat tint = image.clone();
  for (size_t i = 0; i < a.shapes.size(); ++i) {
    const AnnotationShape& shape = a.shapes[i];
    cv::Mat mine = masks.shape_index == static_cast<int>(i);
    if (shape.IsPlane()) {
      tint.setTo(shape.normal ? NormalColour(shape.normal->normalized()) : cv::Scalar(200, 200, 200), mine);
    } else if (shape.IsNonPlane()) {
      cv::Mat hatch(size, CV_8UC3, cv::Scalar(60, 60, 200));
      const int step = static_cast<int>(10 * s);
      for (int k = -size.height; k < size.width; k += step) {
        cv::line(hatch, cv::Point(k, 0), cv::Point(k + size.height, size.height), cv::Scalar(20, 20, 20),
                 std::max(1, static_cast<int>(s)));
      }
      hatch.copyTo(tint, mine);
    }
  }
  cv::Mat out;
  cv::addWeighted(tint, options.alpha, image, 1 - options.alpha, 0, out);

  const double sx = static_cast<double>(size.width) / a.image_width;
  const double sy = static_cast<double>(size.height) / a.image_height;
  for (const AnnotationShape& shape : a.shapes) {
    if ((!shape.IsPlane() && !shape.IsNonPlane()) || shape.points.size() < 3) continue;
    std::vector<cv::Point> poly;
    cv::Point2d centre(0, 0);
    for (const auto& p : shape.points) {
      const cv::Point2d q((p.x() + 0.5) * sx - 0.5, (p.y() + 0.5) * sy - 0.5);
      poly.emplace_back(cv::Point(q));
      centre += q;
    }
    centre *= 1.0 / static_cast<double>(shape.points.size());
    const cv::Scalar outline =
        shape.IsPlane() && shape.normal ? NormalColour(shape.normal->normalized()) : cv::Scalar(60, 60, 220);
    cv::polylines(out, poly, true, cv::Scalar(0, 0, 0), static_cast<int>(3 * s), cv::LINE_AA);
    cv::polylines(out, poly, true, outline, static_cast<int>(std::max(1.0, 1.5 * s)), cv::LINE_AA);
    if (shape.IsPlane() && shape.normal && shape.normal->allFinite() && shape.normal->norm() > 0) {
      // The normal's direction in the image: its x, y components, drawn from the polygon's centre.
      const Eigen::Vector3d n = shape.normal->normalized();
      const double len = 40 * s;
      const cv::Point2d tip = centre + cv::Point2d(n.x(), n.y()) * len;
      cv::arrowedLine(out, centre, tip, cv::Scalar(0, 0, 0), static_cast<int>(4 * s), cv::LINE_AA, 0, 0.25);
      cv::arrowedLine(out, centre, tip, cv::Scalar(255, 255, 255), static_cast<int>(2 * s), cv::LINE_AA, 0, 0.25);
      cv::circle(out, centre, static_cast<int>(3 * s), cv::Scalar(255, 255, 255), cv::FILLED, cv::LINE_AA);
    }
  }
  if (!options.legend) return out;
  // The legend needs about 330 px of height at scale 1; short images are padded below.
  const int panel_height = std::max(size.height, static_cast<int>(370 * s));
  if (out.rows < panel_height) {
    cv::copyMakeBorder(out, out, 0, panel_height - out.rows, 0, 0, cv::BORDER_CONSTANT, cv::Scalar(40, 40, 40));
  }
  cv::Mat panel(panel_height, std::max(170, static_cast<int>(170 * s)), CV_8UC3, cv::Scalar(40, 40, 40));
  DrawLegend(panel, s);
  cv::Mat combined;
  cv::hconcat(out, panel, combined);
  return combined;
}

}  // namespace pdvo
