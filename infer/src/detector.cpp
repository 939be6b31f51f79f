#include "pdvo/infer/detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>

#include "pdvo/common/errors.h"
#include "pdvo/common/logging.h"
#include "pdvo/common/options.h"
#include "pdvo/infer/column_cuts.h"
#include "pdvo/infer/mrf.h"
#include "pdvo/infer/sphere.h"
#include "pdvo/infer/vanishing.h"
#include "pdvo/infer/window_features.h"

namespace pdvo {
namespace {

constexpr double kDegree = M_PI / 180;
constexpr double kMinProbability = 1e-3;   // MRF 1's data terms: -log of probabilities clamped to this
constexpr double kMaxOrientationCost = 4;  // MRF 2's data cost, at most
constexpr double kMaxWordLogOdds = 3;      // a point's two words' plane log-odds, summed, at most this either way
constexpr int kMinColumnPixels = 8;        // a column of a plane's area with fewer pixels has no colour of its own
constexpr int kMinPartPoints = 3;          // a part of a split plane is kept down to this many points

using Clock = std::chrono::steady_clock;
double Ms(Clock::time_point from) { return std::chrono::duration<double, std::milli>(Clock::now() - from).count(); }

// The windows of every size and shape on the grid, spread evenly over the image.
std::vector<cv::Rect> MakeWindows(cv::Size size, const DetectorOptions& o) {
  const int columns = size.width / o.cell, rows = size.height / o.cell;
  std::set<std::tuple<int, int, int, int>> seen;
  std::vector<cv::Rect> windows;
  for (const double side : o.window_sizes) {
    for (const double aspect : o.window_aspects) {
      const int w = std::max(1, static_cast<int>(std::lround(side * std::sqrt(aspect) / o.cell)));
      const int h = std::max(1, static_cast<int>(std::lround(side / std::sqrt(aspect) / o.cell)));
      if (w > columns || h > rows) continue;
      const int sx = std::max(1, static_cast<int>(std::lround((1 - o.overlap) * w)));
      const int sy = std::max(1, static_cast<int>(std::lround((1 - o.overlap) * h)));
      const int nx = (columns - w) / sx + 1, ny = (rows - h) / sy + 1;
      const int ox = (columns - w - (nx - 1) * sx) / 2, oy = (rows - h - (ny - 1) * sy) / 2;
      for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
          const int x = ox + i * sx, y = oy + j * sy;
          if (!seen.insert({x, y, w, h}).second) continue;
          windows.emplace_back(x * o.cell, y * o.cell, w * o.cell, h * o.cell);
        }
      }
    }
  }
  return windows;
}

// The Delaunay triangulation's edges (a < b); points on one pixel position share the first one's vertex.
std::vector<std::pair<int, int>> DelaunayEdges(const std::vector<cv::Point2f>& points, cv::Size size) {
  cv::Subdiv2D subdiv(cv::Rect(-1, -1, size.width + 2, size.height + 2));
  std::vector<int> point_of_vertex;
  for (size_t i = 0; i < points.size(); ++i) {
    const int vertex = subdiv.insert(points[i]);
    if (vertex >= static_cast<int>(point_of_vertex.size())) point_of_vertex.resize(vertex + 1, -1);
    if (point_of_vertex[vertex] < 0) point_of_vertex[vertex] = static_cast<int>(i);
  }
  std::vector<int> leading;  // one edge of each triangle; its other two follow around the triangle
  subdiv.getLeadingEdgeList(leading);
  std::vector<int> all;
  for (const int e : leading) {
    const int next = subdiv.getEdge(e, cv::Subdiv2D::NEXT_AROUND_LEFT);
    all.insert(all.end(), {e, next, subdiv.getEdge(next, cv::Subdiv2D::NEXT_AROUND_LEFT)});
  }
  std::set<std::pair<int, int>> edges;
  for (const int e : all) {
    const int a = subdiv.edgeOrg(e), b = subdiv.edgeDst(e);
    if (a < 0 || b < 0 || a >= static_cast<int>(point_of_vertex.size()) ||
        b >= static_cast<int>(point_of_vertex.size()))
      continue;
    const int pa = point_of_vertex[a], pb = point_of_vertex[b];
    if (pa < 0 || pb < 0 || pa == pb) continue;
    edges.insert({std::min(pa, pb), std::max(pa, pb)});
  }
  return {edges.begin(), edges.end()};
}

// Connected components of the nodes with a label >= 0, over edges joining equal labels; in order of first node.
std::vector<std::vector<int>> Components(int n, const std::vector<std::pair<int, int>>& edges,
                                         const std::vector<int>& label) {
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (const auto& [a, b] : edges) {
    if (label[a] >= 0 && label[a] == label[b]) parent[root(a)] = root(b);
  }
  std::vector<int> index(n, -1);
  std::vector<std::vector<int>> out;
  for (int i = 0; i < n; ++i) {
    if (label[i] < 0) continue;
    const int r = root(i);
    if (index[r] < 0) {
      index[r] = static_cast<int>(out.size());
      out.emplace_back();
    }
    out[index[r]].push_back(i);
  }
  return out;
}

}  // namespace

PointPooling PoolWindows(const std::vector<cv::Point2f>& points, const std::vector<DetectedWindow>& windows,
                         double normal_scale_deg) {
  const size_t n = points.size();
  // The windows' edges cut the image into rectangles whose pixels all lie in the same windows: a point's windows
  // are found once per rectangle, and points held by the same windows (most share a cell) are pooled once.
  std::vector<int> xs, ys;
  for (const DetectedWindow& w : windows) {
    xs.insert(xs.end(), {w.box.x, w.box.x + w.box.width});
    ys.insert(ys.end(), {w.box.y, w.box.y + w.box.height});
  }
  for (std::vector<int>* cuts : {&xs, &ys}) {
    std::sort(cuts->begin(), cuts->end());
    cuts->erase(std::unique(cuts->begin(), cuts->end()), cuts->end());
  }
  std::map<std::pair<long, long>, std::vector<int>> rectangles;  // the windows holding each rectangle
  std::vector<const std::vector<int>*> holding(n);
  for (size_t i = 0; i < n; ++i) {
    const cv::Point p = NearestPixel(points[i]);
    const auto key = std::make_pair(std::upper_bound(xs.begin(), xs.end(), p.x) - xs.begin(),
                                    std::upper_bound(ys.begin(), ys.end(), p.y) - ys.begin());
    auto [at, fresh] = rectangles.try_emplace(key);
    if (fresh) {
      for (size_t k = 0; k < windows.size(); ++k) {
        if (windows[k].box.contains(p)) at->second.push_back(static_cast<int>(k));
      }
    }
    holding[i] = &at->second;
  }
  PointPooling out{std::vector<double>(n, 0.5), std::vector<Eigen::Vector3d>(n, Eigen::Vector3d::Zero())};
  std::map<std::vector<int>, size_t> pooled;
  std::vector<double> probabilities;
  std::vector<Eigen::Vector3d> normals;
  for (size_t i = 0; i < n; ++i) {
    if (holding[i]->empty()) continue;
    const auto [known, fresh] = pooled.try_emplace(*holding[i], i);
    if (!fresh) {
      out.planarity[i] = out.planarity[known->second];
      out.normals[i] = out.normals[known->second];
      continue;
    }
    probabilities.clear();
    normals.clear();
    for (const int k : *holding[i]) {
      probabilities.push_back(windows[static_cast<size_t>(k)].plane_probability);
      normals.push_back(windows[static_cast<size_t>(k)].normal);
    }
    std::vector<double> sorted = probabilities;
    std::sort(sorted.begin(), sorted.end());
    const size_t m = sorted.size();
    out.planarity[i] = m % 2 ? sorted[m / 2] : 0.5 * (sorted[m / 2 - 1] + sorted[m / 2]);
    out.normals[i] = RobustMeanDirection(normals, probabilities, normal_scale_deg);
  }
  return out;
}

bool DetectorOptions::Check() const {
  PDVO_CHECK_OPTION(cell >= 1 && !window_sizes.empty() && !window_aspects.empty());
  for (const double s : window_sizes) PDVO_CHECK_OPTION(s >= cell);
  for (const double a : window_aspects) PDVO_CHECK_OPTION(a > 0 && a <= 16 && a >= 1.0 / 16);
  PDVO_CHECK_OPTION(overlap >= 0 && overlap < 1 && normal_scale_deg > 0 && word_prior_weight >= 0);
  PDVO_CHECK_OPTION(distance_scale > 0 && colour_scale > 0 && plane_smoothness >= 0);
  PDVO_CHECK_OPTION(orientation_bandwidth_deg > 0 && orientation_merge_deg > 0 && max_orientations >= 1);
  PDVO_CHECK_OPTION(orientation_scale_deg > 0 && orientation_smoothness >= 0);
  PDVO_CHECK_OPTION(column_split_penalty >= 0 && azimuth_split_penalty >= 0 && column_split_width >= 1 &&
                    column_join_colour >= 0);
  PDVO_CHECK_OPTION(min_segment_points >= 1 && min_plane_probability >= 0 && min_plane_probability <= 1);
  PDVO_CHECK_OPTION(cell_radius > 0);
  PDVO_CHECK_OPTION(point_quality > 0 && point_quality < 1 && point_min_distance >= 1);
  return true;
}

Detector::Detector(PlaneModel model, const DetectorOptions& options)
    : recogniser_(std::move(model)), options_(options) {
  CheckOptionsOrThrow(options, "detector options");
  if (options.word_prior_weight > 0 && recogniser_.model().word_plane_log_odds.size() == 0) {
    PDVO_LOG(Warning) << "the model has no word log-odds (trained before version 6): the detector runs without its "
                         "words' prior (pdvo train --word-prior-of adds them)";
  }
}

Detections Detector::Detect(const cv::Mat& image, const std::optional<Camera>& camera) const {
  const auto start = Clock::now();
  const DetectorOptions& o = options_;
  const PlaneModel& model = recogniser_.model();
  PDVO_THROW_CHECK(!image.empty() && image.depth() == CV_8U && (image.channels() == 3 || image.channels() == 1),
                   InvalidArgument, "detector: the image must be 8-bit BGR or grey and not empty");
  PDVO_THROW_CHECK(!camera || (camera->width == image.cols && camera->height == image.rows), InvalidArgument,
                   "detector: the image is " << image.cols << "x" << image.rows << ", its camera " << camera->width
                                             << "x" << camera->height);
  Detections d;
  cv::Mat work = ToWorkingSize(image, model.options.working_width, &d.scale);
  if (work.channels() == 1) cv::cvtColor(work, work, cv::COLOR_GRAY2BGR);
  d.image_size = work.size();
  const std::vector<cv::Rect> boxes = MakeWindows(work.size(), o);
  PDVO_THROW_CHECK(!boxes.empty(), InvalidArgument,
                   "detector: a " << work.cols << "x" << work.rows << " image (at the working width) is smaller than "
                                  << "the smallest window");
  std::optional<Camera> working_camera;
  if (camera) working_camera = camera->Rescaled(work.cols, work.rows);
  FeatureOptions points = model.options.features;
  points.quality = o.point_quality;
  points.min_distance = o.point_min_distance;
  const ImageWords words = recogniser_.Describe(work, working_camera, &points);
  d.points = words.points;
  d.times.describe = Ms(start);

  // 1. Windows.
  auto t = Clock::now();
  const WindowFeatures features(words, model, o.cell);
  VanishingOptions window_vanishing = model.options.vanishing;
  window_vanishing.fuse_normals = window_vanishing.fuse_normals && o.fuse_window_normals;
  std::vector<cv::Rect> kept;
  for (const cv::Rect& box : boxes) {
    if (features.Points(box) >= model.options.min_points) kept.push_back(box);
  }
  const Eigen::MatrixXd rows = features.Features(kept);
  const std::vector<RegionPrediction> predictions = recogniser_.PredictRows(rows);
  for (size_t k = 0; k < kept.size(); ++k) {
    const Region region{kept[k], cv::Mat()};
    d.windows.push_back({kept[k], predictions[k].plane_probability,
                         FuseNormal(predictions[k].normal, words.edges, region, window_vanishing)});
  }
  d.times.windows = Ms(t);

  // 2. Per point: the windows that hold it.
  t = Clock::now();
  const int n = static_cast<int>(d.points.size());
  PointPooling pooled = PoolWindows(d.points, d.windows, o.normal_scale_deg);
  d.planarity = std::move(pooled.planarity);
  d.normals = std::move(pooled.normals);
  // The prior of the points' words (version 6 models): trees, cars and sky have words of their own, which windows
  // that mostly see facades outvote.
  const Eigen::VectorXd& word_odds = model.word_plane_log_odds;
  if (o.word_prior_weight > 0 && word_odds.size() > 0) {
    const int colour_offset = model.gradient_words.size();  // the colour words follow the gradient words
    for (int i = 0; i < n; ++i) {
      const double words_say = std::clamp(word_odds(words.gradient[i]) + word_odds(colour_offset + words.colour[i]),
                                          -kMaxWordLogOdds, kMaxWordLogOdds);
      const double p = std::clamp(d.planarity[i], kMinProbability, 1 - kMinProbability);
      d.planarity[i] = 1 / (1 + std::exp(-std::log(p / (1 - p)) - o.word_prior_weight * words_say));
    }
  }
  d.times.pooling = Ms(t);

  // 3. The graph and the two MRFs.
  t = Clock::now();
  const std::vector<std::pair<int, int>> edges = DelaunayEdges(d.points, work.size());
  std::vector<double> weight;
  for (const auto& [a, b] : edges) {
    const cv::Point pa = NearestPixel(d.points[a]), pb = NearestPixel(d.points[b]);
    const cv::Vec3b ca = work.at<cv::Vec3b>(std::clamp(pa.y, 0, work.rows - 1), std::clamp(pa.x, 0, work.cols - 1));
    const cv::Vec3b cb = work.at<cv::Vec3b>(std::clamp(pb.y, 0, work.rows - 1), std::clamp(pb.x, 0, work.cols - 1));
    const double colour = cv::norm(cv::Vec3d(ca) - cv::Vec3d(cb)) / 255;
    const double distance = cv::norm(d.points[a] - d.points[b]);
    weight.push_back(std::exp(-0.5 * std::pow(distance / o.distance_scale, 2)) *
                     std::exp(-0.5 * std::pow(colour / o.colour_scale, 2)));
  }
  BinaryEnergy planes(n);
  for (int i = 0; i < n; ++i) {
    planes.AddUnary(i, -std::log(std::max(1 - d.planarity[i], kMinProbability)),
                    -std::log(std::max(d.planarity[i], kMinProbability)));
  }
  for (size_t e = 0; e < edges.size(); ++e) {
    const double w = o.plane_smoothness * weight[e];
    planes.AddPairwise(edges[e].first, edges[e].second, 0, w, w, 0);
  }
  if (o.mrf_planes) {
    d.plane_label = planes.Minimise();
  } else {
    d.plane_label.resize(n);
    for (int i = 0; i < n; ++i) d.plane_label[i] = d.planarity[i] > 0.5;
  }

  // MRF 2 over the planar points that have a normal.
  std::vector<int> planar;
  std::vector<Eigen::Vector3d> planar_normals;
  std::vector<double> planar_weights;
  std::vector<int> node(n, -1);
  for (int i = 0; i < n; ++i) {
    if (d.plane_label[i] != 1 || d.normals[i].squaredNorm() == 0) continue;
    node[i] = static_cast<int>(planar.size());
    planar.push_back(i);
    planar_normals.push_back(d.normals[i]);
    planar_weights.push_back(d.planarity[i]);
  }
  d.orientation.assign(n, -1);
  std::vector<DirectionMode> modes =
      MeanShiftModes(planar_normals, planar_weights, o.orientation_bandwidth_deg, o.orientation_merge_deg);
  if (static_cast<int>(modes.size()) > o.max_orientations) modes.resize(o.max_orientations);

  if (!modes.empty()) {
    const int k = static_cast<int>(modes.size());
    Eigen::MatrixXd cost(static_cast<Eigen::Index>(planar.size()), k);
    std::vector<int> initial(planar.size(), 0);
    for (size_t p = 0; p < planar.size(); ++p) {
      for (int l = 0; l < k; ++l) {
        const double angle = std::acos(std::clamp(planar_normals[p].dot(modes[l].direction), -1.0, 1.0));
        cost(static_cast<Eigen::Index>(p), l) =
            std::min(std::pow(angle / (o.orientation_scale_deg * kDegree), 2), kMaxOrientationCost);
      }
      cost.row(static_cast<Eigen::Index>(p)).minCoeff(&initial[p]);
    }
    std::vector<PottsEdge> potts;
    for (size_t e = 0; e < edges.size(); ++e) {
      const int a = node[edges[e].first], b = node[edges[e].second];
      if (a >= 0 && b >= 0) potts.push_back({a, b, o.orientation_smoothness * weight[e]});
    }
    const std::vector<int> labels = o.mrf_orientations ? AlphaExpansion(cost, potts, initial) : initial;
    for (size_t p = 0; p < planar.size(); ++p) d.orientation[planar[p]] = labels[p];
  }
  d.times.segmentation = Ms(t);

  // 4. Segments: their areas (Voronoi cells within cell_radius), recognised again.
  t = Clock::now();
  cv::Mat sites(work.size(), CV_8U, cv::Scalar(255)), distance, labels;
  for (const cv::Point2f& p : d.points) {
    const cv::Point q = NearestPixel(p);
    if (q.x >= 0 && q.y >= 0 && q.x < work.cols && q.y < work.rows) sites.at<uchar>(q) = 0;
  }
  std::vector<int> point_of_label;
  if (n > 0) {
    cv::distanceTransform(sites, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
    for (int i = 0; i < n; ++i) {
      const cv::Point q = NearestPixel(d.points[i]);
      if (q.x < 0 || q.y < 0 || q.x >= work.cols || q.y >= work.rows) continue;
      const int label = labels.at<int>(q);
      if (label >= static_cast<int>(point_of_label.size())) point_of_label.resize(label + 1, -1);
      if (point_of_label[label] < 0) point_of_label[label] = i;
    }
  }
  std::vector<int> non_planar(n, -1);
  for (int i = 0; i < n; ++i) non_planar[i] = d.orientation[i] < 0 ? 0 : -1;
  // The members' cells within cell_radius lie in their points' bounding box widened by it (by a quarter more: the
  // distance transform's 5x5 mask approximates Euclidean distances to within a few percent).
  const int reach = static_cast<int>(std::ceil(1.25 * o.cell_radius)) + 1;
  auto area_of = [&](const std::vector<int>& members) {
    std::vector<bool> in(n, false);
    int x0 = work.cols, y0 = work.rows, x1 = -1, y1 = -1;
    for (const int i : members) {
      in[i] = true;
      const cv::Point q = NearestPixel(d.points[i]);
      x0 = std::min(x0, q.x), y0 = std::min(y0, q.y), x1 = std::max(x1, q.x), y1 = std::max(y1, q.y);
    }
    cv::Mat mask(work.size(), CV_8U, cv::Scalar(0));
    for (int y = std::max(0, y0 - reach); y <= std::min(work.rows - 1, y1 + reach); ++y) {
      const int* label = labels.ptr<int>(y);
      const float* dist = distance.ptr<float>(y);
      uchar* out = mask.ptr<uchar>(y);
      for (int x = std::max(0, x0 - reach); x <= std::min(work.cols - 1, x1 + reach); ++x) {
        const int i = label[x] < static_cast<int>(point_of_label.size()) ? point_of_label[label[x]] : -1;
        if (i >= 0 && in[i] && dist[x] <= o.cell_radius) out[x] = 255;
      }
    }
    return mask;
  };
  // A plane segment of these points and this area, recognised again (its final normal and score), or none if the
  // recognition rejects it (without re-recognition: its points' robust mean normal and mean planarity). Where the
  // points' mean normal is horizontal and the recognition's is not, the plane is horizontal (FuseNormal of that
  // mean: the image's vertical, facing the camera): a wide stretch of road and pavement is recognised less surely than
  // by the windows over its parts (docs/detector.md).
  auto plane_of = [&](const std::vector<int>& members, cv::Mat mask) -> std::optional<DetectedSegment> {
    DetectedSegment s;
    s.planar = true;
    s.points = members;
    s.mask = std::move(mask);
    const cv::Rect box = cv::boundingRect(s.mask);
    if (box.area() == 0) return std::nullopt;
    auto points_mean = [&] {  // the members' robust mean normal, weighted by their planarity
      std::vector<Eigen::Vector3d> member_normals;
      std::vector<double> member_weights;
      for (const int i : members) {
        member_normals.push_back(d.normals[i]);
        member_weights.push_back(d.planarity[i]);
      }
      return RobustMeanDirection(member_normals, member_weights, o.normal_scale_deg);
    };
    if (!o.rerecognise) {
      for (const int i : members) s.score += d.planarity[i] / static_cast<double>(members.size());
      s.normal = points_mean();
      return s;
    }
    const Region region{box, s.mask(box).clone()};
    const RegionPrediction p = recogniser_.Recognise(words, region);
    if (!p.valid || p.plane_probability < o.min_plane_probability) return std::nullopt;
    const VanishingOptions& vanishing = model.options.vanishing;
    s.normal = p.normal;
    // Called vertical, but the points say ground: fused as a recognised ground is (the image's vertical).
    if (std::abs(p.normal.dot(words.edges.up)) < vanishing.horizontal_cos) {
      const Eigen::Vector3d mean = points_mean();
      if (std::abs(mean.dot(words.edges.up)) > vanishing.horizontal_cos)
        s.normal = FuseNormal(mean, words.edges, region, vanishing);
    }
    s.score = p.plane_probability;
    return s;
  };
  cv::Mat lab;
  const ColumnCutOptions column_cuts{o.column_split_penalty, o.azimuth_split_penalty, o.column_split_width,
                                     kMinColumnPixels, o.column_join_colour};
  if (o.column_split_penalty > 0 || o.azimuth_split_penalty > 0) {
    work.convertTo(lab, CV_32F, 1.0 / 255);
    cv::cvtColor(lab, lab, cv::COLOR_BGR2Lab);
  }
  for (const std::vector<int>& members : Components(n, edges, d.orientation)) {
    if (static_cast<int>(members.size()) < o.min_segment_points) continue;
    std::optional<DetectedSegment> s = plane_of(members, area_of(members));
    if (!s) continue;
    // A vertical plane is split where its colour changes or its edges turn along the image's columns (one facade
    // meeting the next, FacadeColumnCuts): each part, its points and its area within a run of columns, is recognised
    // again, and takes the whole's recognition if its own fails.
    std::vector<int> cuts;
    if (!lab.empty() && std::abs(s->normal.dot(words.edges.up)) < model.options.vanishing.horizontal_cos)
      cuts = FacadeColumnCuts(lab, words.edges, s->mask, column_cuts, model.options.vanishing);
    if (cuts.empty()) {
      d.segments.push_back(std::move(*s));
      continue;
    }
    std::vector<std::vector<int>> parts(cuts.size() + 1);  // a run's points, whether the graph joins them or not
    for (const int i : members)
      parts[std::upper_bound(cuts.begin(), cuts.end(), NearestPixel(d.points[i]).x) - cuts.begin()].push_back(i);
    for (size_t k = 0; k < parts.size(); ++k) {
      if (static_cast<int>(parts[k].size()) < kMinPartPoints) continue;
      cv::Mat mask = cv::Mat::zeros(s->mask.size(), CV_8U);  // the whole's area, within the run's columns
      const int from = k == 0 ? 0 : cuts[k - 1], to = k == cuts.size() ? mask.cols : cuts[k];
      s->mask.colRange(from, to).copyTo(mask.colRange(from, to));
      if (cv::countNonZero(mask) == 0) continue;
      std::optional<DetectedSegment> p = plane_of(parts[k], mask);
      if (!p) p = DetectedSegment{true, parts[k], mask, s->normal, s->score};
      d.segments.push_back(std::move(*p));
    }
  }
  for (const std::vector<int>& members : Components(n, edges, non_planar)) {
    if (static_cast<int>(members.size()) < o.min_segment_points) continue;
    DetectedSegment s;
    s.points = members;
    s.mask = area_of(members);
    double planarity = 0;
    for (const int i : members) planarity += d.planarity[i];
    s.score = 1 - planarity / static_cast<double>(members.size());
    d.segments.push_back(std::move(s));
  }
  d.times.segments = Ms(t);
  d.times.total = Ms(start);
  return d;
}

}  // namespace pdvo
