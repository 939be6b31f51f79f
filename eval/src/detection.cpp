#include "pdvo/eval/detection.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "compare.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/common/geometry.h"

namespace pdvo {
namespace {

double Ratio(double a, double b) { return b > 0 ? a / b : 0.0; }
double F1(double p, double r) { return p + r > 0 ? 2 * p * r / (p + r) : 0.0; }
using detail::Median;
// n choose 2.
double Pairs(double n) { return 0.5 * n * (n - 1); }
nlohmann::json ToJson(const Unmatched& u) {
  return {{"turned", u.turned},
          {"merged", u.merged()},
          {"merged_with",
           {{"parallel", u.merged_parallel},
            {"angled", u.merged_angled},
            {"nonplane", u.merged_nonplane},
            {"unannotated", u.merged_unannotated}}},
          {"fragmented", u.fragmented},
          {"missed", u.missed}};
}

}  // namespace

Unmatched& Unmatched::operator+=(const Unmatched& o) {
  turned += o.turned, fragmented += o.fragmented, missed += o.missed;
  merged_parallel += o.merged_parallel, merged_angled += o.merged_angled;
  merged_nonplane += o.merged_nonplane, merged_unannotated += o.merged_unannotated;
  return *this;
}

DetectionScore ScoreDetection(const Annotation& reference, const Annotation& detection,
                              const DetectionScoreOptions& options) {
  const cv::Size size = detail::ComparisonSize(reference, detection, options.max_width, "detection score");
  const AnnotationMasks ref = Rasterise(reference, size), det = Rasterise(detection, size);
  // Planes, not shapes: the pieces of one plane (one group_id) are one plane.
  const AnnotationPlanes ref_planes = PlanesOf(reference), det_planes = PlanesOf(detection);
  const auto normal_of = [](const Annotation& a, const AnnotationPlanes& planes, int plane) -> const auto& {
    return a.shapes[planes.largest[plane]].normal;  // the plane's: its largest piece's
  };
  DetectionScore s;
  // Per reference plane and per detected plane: pixel counts and their overlaps.
  std::map<int, long> ref_area, det_area;
  std::map<std::pair<int, int>, long> overlap;  // (reference plane, detected plane or -1) on reference planes
  std::map<int, long> det_on_nonplane;          // per detected plane, its pixels on reference non-plane
  for (int y = 0; y < size.height; ++y) {
    const uchar* rl = ref.label.ptr<uchar>(y);
    const uchar* dl = det.label.ptr<uchar>(y);
    const int* rs = ref.shape_index.ptr<int>(y);
    const int* ds = det.shape_index.ptr<int>(y);
    for (int x = 0; x < size.width; ++x) {
      const bool det_plane = dl[x] == kMaskPlane, det_nonplane = dl[x] == kMaskNonPlane;
      const int d = det_plane ? det_planes.of_shape[ds[x]] : -1;
      if (det_plane) ++det_area[d];
      if (rl[x] == kMaskPlane) {
        (det_plane ? s.plane_as_plane : det_nonplane ? s.plane_as_nonplane : s.plane_as_none) += 1;
        ++ref_area[ref_planes.of_shape[rs[x]]];
        ++overlap[{ref_planes.of_shape[rs[x]], d}];
      } else if (rl[x] == kMaskNonPlane) {
        if (det_plane) ++det_on_nonplane[d];
        (det_plane ? s.nonplane_as_plane : det_nonplane ? s.nonplane_as_nonplane : s.nonplane_as_none) += 1;
      }
    }
  }
  // Plane recall: IoU of each reference plane with each detected plane (over all pixels, not only annotated).
  const double image = static_cast<double>(size.area());
  std::map<int, bool> det_matched;
  for (const auto& [r, area] : ref_area) {
    const std::optional<Eigen::Vector3d>& normal = normal_of(reference, ref_planes, r);
    const bool counted = area >= options.min_plane_share * image;
    s.reference_planes += counted;
    // Its match: the detected plane of highest IoU, if at least match_iou.
    int best = -1;
    double best_iou = options.match_iou;
    long largest = 0, detected = 0;  // the largest overlap with one detected plane; all detected plane pixels on it
    int largest_plane = -1;
    for (const auto& [key, inter] : overlap) {
      if (key.first != r || key.second < 0) continue;
      const int d = key.second;
      const double iou = inter / static_cast<double>(area + det_area[d] - inter);
      if (iou >= best_iou) best = d, best_iou = iou;
      if (inter > largest) largest = inter, largest_plane = d;
      detected += inter;
    }
    double angle = 180;
    if (best >= 0) {
      det_matched[best] = true;
      const std::optional<Eigen::Vector3d>& detected_normal = normal_of(detection, det_planes, best);
      if (normal && detected_normal) {
        angle = AngleDeg(*normal, *detected_normal);
        s.normal_errors_deg.push_back(angle);
      }
    }
    if (!counted) continue;
    s.matched_10 += angle <= 10;
    s.matched_30 += angle <= 30;
    if (angle <= 30) continue;
    Unmatched& u = s.unmatched;
    if (best >= 0) {
      ++u.turned;
    } else if (2 * largest >= area) {  // merged: put down to where the rest of that detected plane lies
      double parallel = 0, angled = 0;
      for (const auto& [key, inter] : overlap) {
        if (key.second != largest_plane || key.first == r) continue;
        const std::optional<Eigen::Vector3d>& other = normal_of(reference, ref_planes, key.first);
        (normal && other && AngleDeg(*normal, *other) <= 30 ? parallel : angled) += inter;
      }
      const double nonplane = det_on_nonplane[largest_plane];
      const double unannotated = det_area[largest_plane] - largest - parallel - angled - nonplane;
      const double most = std::max({parallel, angled, nonplane, unannotated});
      ++(most == parallel   ? u.merged_parallel
         : most == angled   ? u.merged_angled
         : most == nonplane ? u.merged_nonplane
                            : u.merged_unannotated);
    } else {
      ++(2 * detected >= area ? u.fragmented : u.missed);
    }
  }
  for (const auto& [d, area] : det_area) s.spurious_planes += !det_matched[d];
  // Segmentation over the reference plane pixels, from the contingency table `overlap`.
  double n = 0;
  std::map<int, double> a, b;
  for (const auto& [key, count] : overlap) {
    n += count;
    a[key.first] += count;
    b[key.second] += count;
  }
  s.segmentation_pixels = static_cast<long>(n);
  if (n > 1) {
    double same = 0, sa = 0, sb = 0, information = 0, ha = 0, hb = 0;
    for (const auto& [key, count] : overlap) {
      same += Pairs(count);
      information += count / n * std::log2(count * n / (a[key.first] * b[key.second]));
    }
    for (const auto& [k, v] : a) sa += Pairs(v), ha -= v / n * std::log2(v / n);
    for (const auto& [k, v] : b) sb += Pairs(v), hb -= v / n * std::log2(v / n);
    s.rand_index = 1 + (2 * same - sa - sb) / Pairs(n);
    s.variation_of_information = std::max(0.0, ha + hb - 2 * information);
    double covering = 0;
    for (const auto& [r, area] : a) {
      double best = 0;
      for (const auto& [key, inter] : overlap) {
        if (key.first != r || key.second < 0) continue;
        best = std::max(best,
                        static_cast<double>(inter) / static_cast<double>(ref_area[r] + det_area[key.second] - inter));
      }
      covering += area * best;
    }
    s.covering = covering / n;
  }
  return s;
}

DetectionSummary Summarise(const std::vector<DetectionScore>& scores) {
  DetectionSummary m;
  double pp = 0, pn = 0, p0 = 0, np = 0, nn = 0, n0 = 0, matched_10 = 0, matched_30 = 0;
  std::vector<double> errors;
  int segmented = 0;
  for (const DetectionScore& s : scores) {
    ++m.images;
    pp += s.plane_as_plane, pn += s.plane_as_nonplane, p0 += s.plane_as_none;
    np += s.nonplane_as_plane, nn += s.nonplane_as_nonplane, n0 += s.nonplane_as_none;
    m.reference_planes += s.reference_planes;
    matched_10 += s.matched_10, matched_30 += s.matched_30;
    errors.insert(errors.end(), s.normal_errors_deg.begin(), s.normal_errors_deg.end());
    m.spurious_planes += s.spurious_planes;
    m.unmatched += s.unmatched;
    if (s.segmentation_pixels > 1) {
      ++segmented;
      m.rand_index += s.rand_index;
      m.variation_of_information += s.variation_of_information;
      m.covering += s.covering;
    }
  }
  m.plane_precision = Ratio(pp, pp + np);
  m.plane_recall = Ratio(pp, pp + pn + p0);
  m.plane_f1 = F1(m.plane_precision, m.plane_recall);
  m.nonplane_precision = Ratio(nn, nn + pn);
  m.nonplane_recall = Ratio(nn, nn + np + n0);
  m.nonplane_f1 = F1(m.nonplane_precision, m.nonplane_recall);
  m.false_plane_area = Ratio(np, pp + np);
  m.plane_recall_10 = Ratio(matched_10, m.reference_planes);
  m.plane_recall_30 = Ratio(matched_30, m.reference_planes);
  for (const double e : errors) m.mean_normal_error_deg += e / static_cast<double>(errors.size());
  m.median_normal_error_deg = Median(errors);
  if (segmented > 0) {
    m.rand_index /= segmented;
    m.variation_of_information /= segmented;
    m.covering /= segmented;
  }
  return m;
}

nlohmann::json ToJson(const std::vector<DetectionScore>& scores, const DetectionScoreOptions& options) {
  const DetectionSummary m = Summarise(scores);
  nlohmann::json images = nlohmann::json::array();
  for (const DetectionScore& s : scores) {
    images.push_back({{"name", s.name},
                      {"pixels",
                       {{"plane_as_plane", s.plane_as_plane},
                        {"plane_as_nonplane", s.plane_as_nonplane},
                        {"plane_as_none", s.plane_as_none},
                        {"nonplane_as_plane", s.nonplane_as_plane},
                        {"nonplane_as_nonplane", s.nonplane_as_nonplane},
                        {"nonplane_as_none", s.nonplane_as_none}}},
                      {"reference_planes", s.reference_planes},
                      {"matched_10", s.matched_10},
                      {"matched_30", s.matched_30},
                      {"normal_errors_deg", s.normal_errors_deg},
                      {"spurious_planes", s.spurious_planes},
                      {"unmatched", ToJson(s.unmatched)},
                      {"rand_index", s.rand_index},
                      {"variation_of_information", s.variation_of_information},
                      {"covering", s.covering}});
  }
  const nlohmann::json summary = {{"images", m.images},
                                  {"plane_precision", m.plane_precision},
                                  {"plane_recall", m.plane_recall},
                                  {"plane_f1", m.plane_f1},
                                  {"nonplane_precision", m.nonplane_precision},
                                  {"nonplane_recall", m.nonplane_recall},
                                  {"nonplane_f1", m.nonplane_f1},
                                  {"false_plane_area", m.false_plane_area},
                                  {"reference_planes", m.reference_planes},
                                  {"plane_recall_10", m.plane_recall_10},
                                  {"plane_recall_30", m.plane_recall_30},
                                  {"mean_normal_error_deg", m.mean_normal_error_deg},
                                  {"median_normal_error_deg", m.median_normal_error_deg},
                                  {"spurious_planes", m.spurious_planes},
                                  {"unmatched", ToJson(m.unmatched)},
                                  {"rand_index", m.rand_index},
                                  {"variation_of_information_bits", m.variation_of_information},
                                  {"covering", m.covering}};
  const std::string how =
      "pixels scored where the reference annotates; planes matched by IoU >= " + std::to_string(options.match_iou) +
      "; plane recall over reference planes of at least " + std::to_string(options.min_plane_share) + " of the image";
  return {{"how", how}, {"summary", summary}, {"images", images}};
}

}  // namespace pdvo
