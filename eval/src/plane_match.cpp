#include "pdvo/eval/plane_match.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "compare.h"
#include "pdvo/annotations/raster.h"
#include "pdvo/common/errors.h"
#include "pdvo/eval/recognition.h"

namespace pdvo {
namespace {

using detail::Median;

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

double Mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

}  // namespace

PlaneComparison ComparePlanes(const Annotation& reference, const Annotation& estimate,
                              const PlaneMatchOptions& options) {
  const cv::Size size = detail::ComparisonSize(reference, estimate, options.max_width, "compare");
  // Each plane's mask, the union of its pieces' (PlanesOf), and its largest piece, which stands for it.
  auto plane_masks = [&](const Annotation& a, std::vector<int>* index) {
    const AnnotationPlanes planes = PlanesOf(a);
    std::vector<cv::Mat> masks(planes.largest.size());
    for (size_t i = 0; i < a.shapes.size(); ++i) {
      const int p = planes.of_shape[i];
      if (p < 0) continue;
      const cv::Mat piece = RasteriseShape(a.shapes[i], a, size);
      masks[p] = masks[p].empty() ? piece : (masks[p] | piece);
    }
    *index = planes.largest;
    return masks;
  };
  std::vector<int> ref_index, est_index;
  const std::vector<cv::Mat> ref = plane_masks(reference, &ref_index);
  const std::vector<cv::Mat> est = plane_masks(estimate, &est_index);

  struct Candidate {
    double iou;
    size_t r, e;
  };
  std::vector<Candidate> candidates;
  for (size_t r = 0; r < ref.size(); ++r) {
    const int ref_area = cv::countNonZero(ref[r]);
    for (size_t e = 0; e < est.size(); ++e) {
      const int inter = cv::countNonZero(ref[r] & est[e]);
      if (inter == 0) continue;
      const double iou = inter / static_cast<double>(ref_area + cv::countNonZero(est[e]) - inter);
      if (iou >= options.min_iou) candidates.push_back({iou, r, e});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.iou > b.iou; });
  PlaneComparison out;
  out.reference_planes = static_cast<int>(ref.size());
  out.estimated_planes = static_cast<int>(est.size());
  std::vector<bool> ref_used(ref.size(), false), est_used(est.size(), false);
  for (const Candidate& c : candidates) {
    if (ref_used[c.r] || est_used[c.e]) continue;
    ref_used[c.r] = est_used[c.e] = true;
    PlaneMatch m;
    m.reference_shape = ref_index[c.r];
    m.estimated_shape = est_index[c.e];
    m.iou = c.iou;
    const auto& nr = reference.shapes[m.reference_shape].normal;
    const auto& ne = estimate.shapes[m.estimated_shape].normal;
    if (nr && ne && nr->norm() > 0 && ne->norm() > 0) m.normal_angle_deg = AngleDegrees(*nr, *ne);
    out.matches.push_back(m);
  }
  return out;
}

PlaneComparisonSummary Summarise(const std::vector<PlaneComparison>& comparisons) {
  PlaneComparisonSummary s;
  std::vector<double> ious, matched_ious, angles;
  for (const PlaneComparison& c : comparisons) {
    ++s.frames;
    s.reference_planes += c.reference_planes;
    s.matched += static_cast<int>(c.matches.size());
    for (const PlaneMatch& m : c.matches) {
      ious.push_back(m.iou);
      matched_ious.push_back(m.iou);
      if (m.normal_angle_deg >= 0) angles.push_back(m.normal_angle_deg);
    }
    // Unmatched reference planes count as IoU 0.
    for (int k = static_cast<int>(c.matches.size()); k < c.reference_planes; ++k) ious.push_back(0.0);
  }
  s.median_iou = Median(ious);
  s.mean_iou = Mean(ious);
  s.median_matched_iou = Median(matched_ious);
  s.median_normal_angle_deg = Median(angles);
  s.mean_normal_angle_deg = Mean(angles);
  s.p90_normal_angle_deg = Percentile(angles, 0.9);
  return s;
}

nlohmann::json ToJson(const std::vector<PlaneComparison>& comparisons) {
  const PlaneComparisonSummary s = Summarise(comparisons);
  nlohmann::json j;
  j["summary"] = {{"frames", s.frames},
                  {"reference_planes", s.reference_planes},
                  {"matched", s.matched},
                  {"median_iou", s.median_iou},
                  {"mean_iou", s.mean_iou},
                  {"median_matched_iou", s.median_matched_iou},
                  {"median_normal_angle_deg", s.median_normal_angle_deg},
                  {"mean_normal_angle_deg", s.mean_normal_angle_deg},
                  {"p90_normal_angle_deg", s.p90_normal_angle_deg}};
  nlohmann::json frames = nlohmann::json::array();
  for (const PlaneComparison& c : comparisons) {
    nlohmann::json matches = nlohmann::json::array();
    for (const PlaneMatch& m : c.matches) {
      matches.push_back({{"reference_shape", m.reference_shape},
                         {"estimated_shape", m.estimated_shape},
                         {"iou", m.iou},
                         {"normal_angle_deg", m.normal_angle_deg}});
    }
    frames.push_back({{"name", c.name},
                      {"reference_planes", c.reference_planes},
                      {"estimated_planes", c.estimated_planes},
                      {"matches", matches}});
  }
  j["frames"] = frames;
  return j;
}

double PlanePurity::Share(int min_points, long* points) const {
  long all = 0, on_main = 0;
  for (const auto& [group, by_label] : counts_) {
    int n = 0, most = 0;
    for (const auto& [label, count] : by_label) {
      n += count;
      most = std::max(most, count);
    }
    if (n < min_points) continue;
    all += n;
    on_main += most;
  }
  if (points) *points = all;
  return all > 0 ? static_cast<double>(on_main) / all : 0.0;
}

std::optional<int> PlanePurity::MainLabel(int frame, int plane, int min_points) const {
  const auto group = counts_.find({frame, plane});
  if (group == counts_.end()) return std::nullopt;
  int n = 0, most = 0, main = 0;
  for (const auto& [label, count] : group->second) {
    n += count;
    if (count > most) {
      most = count;
      main = label;
    }
  }
  return n >= min_points ? std::optional<int>(main) : std::nullopt;
}

namespace detail {

cv::Size ComparisonSize(const Annotation& reference, const Annotation& estimate, int max_width, const char* what) {
  CheckSameImageSize(reference, "the reference", estimate, std::string(what) + ": the estimate");
  const double scale = std::min(1.0, static_cast<double>(max_width) / reference.image_width);
  return {static_cast<int>(std::lround(reference.image_width * scale)),
          static_cast<int>(std::lround(reference.image_height * scale))};
}

double Median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace detail
}  // namespace pdvo
