#include "pdvo/sim/street.h"

#include <cmath>
#include <random>

#include "pdvo/common/errors.h"
#include "pdvo/common/options.h"

namespace pdvo::sim {

bool StreetOptions::Check() const {
  PDVO_CHECK_OPTION(min_segment_length >= 10 && max_segment_length >= min_segment_length);
  PDVO_CHECK_OPTION(max_turn_deg >= 0 && max_turn_deg <= 60);
  PDVO_CHECK_OPTION(road_width >= 4 && pavement_width >= 1);
  PDVO_CHECK_OPTION(min_building_width >= 2 && max_building_width >= min_building_width);
  PDVO_CHECK_OPTION(min_building_height >= 3 && max_building_height >= min_building_height);
  PDVO_CHECK_OPTION(max_setback >= 0 && max_setback <= 5);
  PDVO_CHECK_OPTION(tree_spacing > 2 && car_spacing > 5 && pole_spacing > 2);
  return true;
}

bool WalkOptions::Check() const {
  PDVO_CHECK_OPTION(speed > 0 && fps > 0);
  PDVO_CHECK_OPTION(eye_height > 0.3 && eye_height < 3);
  PDVO_CHECK_OPTION(step_frequency >= 0 && bob >= 0 && sway >= 0 && shake_deg >= 0);
  PDVO_CHECK_OPTION(look_deg >= 0 && look_deg <= 180);
  PDVO_CHECK_OPTION(corner_smoothing > 0 && corner_smoothing <= 50);
  PDVO_CHECK_OPTION(std::abs(lateral_offset) < 3);
  return true;
}

const char* MaterialName(Material m) {
  switch (m) {
    case Material::kBrick: return "brick";
    case Material::kRender: return "render";
    case Material::kStone: return "stone";
    case Material::kRoad: return "road";
    case Material::kPavement: return "pavement";
    case Material::kLeaves: return "leaves";
    case Material::kBark: return "bark";
    case Material::kMetal: return "metal";
    case Material::kCarPaint: return "car paint";
  }
  return "?";
}

double Street::Length() const {
  double length = 0;
  for (size_t i = 0; i + 1 < centreline.size(); ++i) length += (centreline[i + 1] - centreline[i]).norm();
  if (loop && centreline.size() > 2) length += (centreline.front() - centreline.back()).norm();
  return length;
}

namespace {

const Eigen::Vector3d kUp(0, -1, 0);  // y points down

// To the right of a walker heading along d on the ground: d = +z gives +x.
Eigen::Vector3d RightOf(const Eigen::Vector3d& d) { return Eigen::Vector3d(d.z(), 0, -d.x()); }

class StreetBuilder {
 public:
  StreetBuilder(const StreetOptions& o, uint64_t seed) : o_(o), rng_(seed) {}

  double Uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng_); }
  bool Chance(double p) { return Uniform(0, 1) < p; }

  void AddPlane(Material material, std::vector<Eigen::Vector3d> polygon, const Eigen::Vector3d& axis_u,
                const Eigen::Vector3d& axis_v) {
    WorldPlane p;
    p.id = static_cast<int>(street_.planes.size());
    p.material = material;
    p.normal = axis_u.cross(axis_v).normalized();
    p.origin = polygon[0];
    p.axis_u = axis_u.normalized();
    p.axis_v = axis_v.normalized();
    // Callers pass axes with u x v pointing to the street (or up).
    p.distance = -p.normal.dot(p.origin);
    double umin = 1e18, umax = -1e18, vmin = 1e18, vmax = -1e18;
    for (const auto& x : polygon) {
      const double u = (x - p.origin).dot(p.axis_u), v = (x - p.origin).dot(p.axis_v);
      umin = std::min(umin, u), umax = std::max(umax, u), vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    }
    p.origin += umin * p.axis_u + vmin * p.axis_v;
    p.width = umax - umin;
    p.height = vmax - vmin;
    p.polygon = std::move(polygon);
    p.texture_seed = static_cast<uint32_t>(rng_());
    street_.planes.push_back(std::move(p));
  }

  void AddBlob(WorldBlob::Kind kind, Material material, const Eigen::Vector3d& centre, const Eigen::Vector3d& radii,
               double yaw, const Eigen::Vector3d& colour) {
    WorldBlob b;
    b.id = static_cast<int>(street_.blobs.size());
    b.kind = kind;
    b.material = material;
    b.centre = centre;
    b.radii = radii;
    b.yaw = yaw;
    b.colour = colour;
    street_.blobs.push_back(b);
  }

  // A quad on the ground between offsets a < b from the centreline, from vertex i to i+1.
  void AddGroundStrip(size_t i, double a, double b, Material material) {
    const Eigen::Vector3d d = Direction(i);
    // right x d points up (-y).
    AddPlane(material, {Offset(i, a), Offset(i, b), Offset(i + 1, b), Offset(i + 1, a)}, RightOf(d), d);
  }

  Street Build(double min_length);

 private:
  size_t Count() const { return street_.centreline.size(); }
  const Eigen::Vector3d& Vertex(size_t i) const { return street_.centreline[i % Count()]; }
  Eigen::Vector3d Direction(size_t i) const { return (Vertex(i + 1) - Vertex(i)).normalized(); }
  size_t Segments() const { return street_.loop ? Count() : Count() - 1; }
  // The mitre at vertex v: offsetting by o along it keeps both neighbouring edges at distance o.
  Eigen::Vector3d Mitre(size_t v) const {
    const bool open_start = !street_.loop && v == 0, open_end = !street_.loop && v + 1 == Count();
    if (open_start) return RightOf(Direction(0));
    if (open_end) return RightOf(Direction(v - 1));
    const Eigen::Vector3d a = RightOf(Direction((v + Count() - 1) % Count())), b = RightOf(Direction(v));
    return (a + b) / (1 + a.dot(b));
  }
  // The point at offset o (positive: right) at vertex v.
  Eigen::Vector3d Offset(size_t v, double o) const { return Vertex(v) + o * Mitre(v % Count()); }

  void AddBuildings(size_t i, int side);
  void AddClutter(size_t i, int side);
  void AddEndWall(size_t v, const Eigen::Vector3d& facing);

  StreetOptions o_;
  std::mt19937_64 rng_;
  Street street_;
};

void StreetBuilder::AddBuildings(size_t i, int side) {
  const Eigen::Vector3d d = Direction(i), r = RightOf(d);
  const double base = o_.road_width / 2 + o_.pavement_width;
  const Eigen::Vector3d a0 = Offset(i, side * base), b0 = Offset(i + 1, side * base);
  const double length = (b0 - a0).dot(d);
  // Split the frontage into buildings; the first and last stand on the base line so corners close.
  std::vector<double> cuts = {0};
  while (length - cuts.back() > o_.max_building_width) {
    cuts.push_back(cuts.back() + Uniform(o_.min_building_width, o_.max_building_width));
  }
  if (cuts.size() > 1 && length - cuts.back() < o_.min_building_width) cuts.pop_back();
  cuts.push_back(length);
  const size_t n = cuts.size() - 1;
  std::vector<double> setback(n), height(n);
  std::vector<Material> material(n);
  for (size_t k = 0; k < n; ++k) {
    setback[k] = (k == 0 || k + 1 == n || Chance(0.35)) ? 0.0 : Uniform(0.3, o_.max_setback);
    height[k] = Uniform(o_.min_building_height, o_.max_building_height);
    const double m = Uniform(0, 3);
    material[k] = m < 1 ? Material::kBrick : m < 2 ? Material::kRender : Material::kStone;
  }
  for (size_t k = 0; k < n; ++k) {
    const Eigen::Vector3d shift = side * setback[k] * r;
    const Eigen::Vector3d p0 = a0 + cuts[k] * d + shift, p1 = a0 + cuts[k + 1] * d + shift;
    const Eigen::Vector3d top = height[k] * kUp;
    // u along the facade with u x v pointing to the street.
    const Eigen::Vector3d u = side > 0 ? Eigen::Vector3d(-d) : d;
    AddPlane(material[k], {p0, p1, p1 + top, p0 + top}, u, kUp);
    // Where the next building stands further back (or forward), the protruding one shows a side wall.
    if (k + 1 < n && std::abs(setback[k] - setback[k + 1]) > 1e-9) {
      const bool this_protrudes = setback[k] < setback[k + 1];
      const size_t front = this_protrudes ? k : k + 1;
      const double lo = std::min(setback[k], setback[k + 1]), hi = std::max(setback[k], setback[k + 1]);
      const Eigen::Vector3d at = a0 + cuts[k + 1] * d;
      const Eigen::Vector3d w0 = at + side * lo * r, w1 = at + side * hi * r;
      const Eigen::Vector3d wall_top = height[front] * kUp;
      // The wall faces +d if this building protrudes (it looks at the recess after it), else -d.
      const Eigen::Vector3d normal = this_protrudes ? d : Eigen::Vector3d(-d);
      const Eigen::Vector3d wu = kUp.cross(normal).normalized();  // so that wu x up = normal
      AddPlane(material[front], {w0, w1, w1 + wall_top, w0 + wall_top}, wu, kUp);
    }
  }
}

void StreetBuilder::AddClutter(size_t i, int side) {
  const Eigen::Vector3d d = Direction(i), r = RightOf(d);
  const double yaw = std::atan2(d.x(), d.z());
  const double half = o_.road_width / 2;
  const Eigen::Vector3d start = Vertex(i);
  const double length = (Vertex(i + 1) - start).norm();
  auto along = [&](double t, double offset, double height) {
    return Eigen::Vector3d(start + t * d + side * offset * r + height * kUp);
  };
  // Trees and bushes on the pavement.
  for (double t = Uniform(3, o_.tree_spacing); t < length - 4; t += o_.tree_spacing * Uniform(0.6, 1.4)) {
    const double offset = half + o_.pavement_width * Uniform(0.45, 0.7);
    AddBlob(WorldBlob::Kind::kCylinder, Material::kBark, along(t, offset, 1.4), {0.14, 1.4, 0.14}, 0,
            {0.18, 0.25, 0.32});
    const Eigen::Vector3d crown = along(t, offset, Uniform(3.2, 4.2));
    const int parts = 5 + static_cast<int>(Uniform(0, 4));
    const Eigen::Vector3d green(Uniform(0.1, 0.25), Uniform(0.4, 0.6), Uniform(0.15, 0.3));
    for (int k = 0; k < parts; ++k) {
      const double s = Uniform(0.6, 1.1);
      AddBlob(WorldBlob::Kind::kEllipsoid, Material::kLeaves,
              crown + Eigen::Vector3d(Uniform(-0.9, 0.9), Uniform(-0.7, 0.6), Uniform(-0.9, 0.9)), {s, s * 0.85, s}, 0,
              green);
    }
    if (Chance(0.4) && t + o_.tree_spacing / 2 < length - 3) {  // bushes stay on their own segment
      const Eigen::Vector3d bush = along(t + o_.tree_spacing / 2, half + o_.pavement_width - 0.5, 0.35);
      for (int k = 0; k < 3; ++k) {
        AddBlob(WorldBlob::Kind::kEllipsoid, Material::kLeaves,
                bush + Eigen::Vector3d(Uniform(-0.5, 0.5), 0, Uniform(-0.5, 0.5)), {0.5, 0.4, 0.5}, 0, green * 0.8);
      }
    }
  }
  // Parked cars along the kerb: a body and a cabin.
  for (double t = Uniform(4, o_.car_spacing); t < length - 5; t += o_.car_spacing * Uniform(0.5, 1.5)) {
    const Eigen::Vector3d paint(Uniform(0.1, 0.9), Uniform(0.1, 0.9), Uniform(0.1, 0.9));
    AddBlob(WorldBlob::Kind::kEllipsoid, Material::kCarPaint, along(t, half - 1.1, 0.7), {0.9, 0.5, 2.2}, yaw, paint);
    AddBlob(WorldBlob::Kind::kEllipsoid, Material::kCarPaint, along(t - 0.2, half - 1.1, 1.2), {0.75, 0.4, 1.2}, yaw,
            paint * 0.7);
  }
  // Poles at the kerb.
  for (double t = Uniform(2, o_.pole_spacing); t < length - 2; t += o_.pole_spacing * Uniform(0.8, 1.2)) {
    AddBlob(WorldBlob::Kind::kCylinder, Material::kMetal, along(t, half + 0.3, 2.0), {0.06, 2.0, 0.06}, 0,
            {0.35, 0.35, 0.35});
  }
}

void StreetBuilder::AddEndWall(size_t v, const Eigen::Vector3d& facing) {
  const double half = o_.road_width / 2 + o_.pavement_width + o_.max_setback + 1;
  const Eigen::Vector3d r = RightOf(-facing);
  const Eigen::Vector3d c = Vertex(v) - facing * 1.0;
  const Eigen::Vector3d top = 16.0 * kUp;
  const Eigen::Vector3d p0 = c - half * r, p1 = c + half * r;
  const Eigen::Vector3d u = kUp.cross(facing).normalized();  // so that u x up = facing
  AddPlane(Material::kRender, {p0, p1, p1 + top, p0 + top}, u, kUp);
}

Street StreetBuilder::Build(double min_length) {
  street_.loop = o_.loop;
  if (o_.loop) {
    // Vertices on a circle, jittered; enough of them for segments of the requested length.
    const double mean = (o_.min_segment_length + o_.max_segment_length) / 2;
    const int n = std::max(4, static_cast<int>(std::ceil(min_length / mean)));
    const double radius = mean / (2 * std::sin(M_PI / n));
    for (int k = 0; k < n; ++k) {
      const double angle = 2 * M_PI * (k + Uniform(-0.2, 0.2)) / n;
      street_.centreline.emplace_back(radius * std::cos(angle), 0, radius * std::sin(angle));
    }
  } else {
    Eigen::Vector3d p(0, 0, 0);
    double heading = 0, length = 0;
    double sign = Chance(0.5) ? 1 : -1;
    street_.centreline.push_back(p);
    while (length < min_length || street_.centreline.size() < 3) {
      const double l = Uniform(o_.min_segment_length, o_.max_segment_length);
      p += l * Eigen::Vector3d(std::sin(heading), 0, std::cos(heading));
      street_.centreline.push_back(p);
      length += l;
      heading += sign * Uniform(0.3, 1.0) * o_.max_turn_deg * M_PI / 180;
      sign = -sign;
    }
  }
  const double half = o_.road_width / 2, kerb = half + o_.pavement_width + o_.max_setback;
  for (size_t i = 0; i < Segments(); ++i) {
    AddGroundStrip(i, -half, half, Material::kRoad);
    AddGroundStrip(i, half, kerb, Material::kPavement);
    AddGroundStrip(i, -kerb, -half, Material::kPavement);
    for (int side : {1, -1}) {
      AddBuildings(i, side);
      AddClutter(i, side);
    }
  }
  if (!o_.loop) {
    AddEndWall(0, Direction(0));                       // behind the start, facing along the street
    AddEndWall(Count() - 1, -Direction(Count() - 2));  // beyond the end, facing back
  }
  return std::move(street_);
}

}  // namespace

Street GenerateStreet(const StreetOptions& options, double min_length, uint64_t seed) {
  CheckOptionsOrThrow(options, "street options");
  StreetBuilder builder(options, seed);
  Street street = builder.Build(min_length);
  for (WorldPlane& a : street.planes) {
    a.surface = a.id;
    for (const WorldPlane& b : street.planes) {
      if (b.id >= a.id) break;
      if (a.normal.dot(b.normal) > 1 - 1e-9 && std::abs(a.distance - b.distance) < 1e-6) {
        a.surface = b.surface;
        break;
      }
    }
  }
  return street;
}

namespace {
// The point at arc length s along the centreline (wrapping on a loop, clamped on an open street).
Eigen::Vector3d PointAt(const Street& street, double s) {
  const size_t n = street.centreline.size();
  const size_t segments = street.loop ? n : n - 1;
  const double total = street.Length();
  s = street.loop ? std::fmod(std::fmod(s, total) + total, total) : std::clamp(s, 0.0, total);
  for (size_t i = 0; i < segments; ++i) {
    const Eigen::Vector3d& a = street.centreline[i];
    const Eigen::Vector3d& b = street.centreline[(i + 1) % n];
    const double l = (b - a).norm();
    if (s <= l || i + 1 == segments) return a + (b - a) * std::min(1.0, s / l);
    s -= l;
  }
  return street.centreline.back();
}

// The centreline averaged over +-`half_width` m, which rounds the corners.
Eigen::Vector3d SmoothPointAt(const Street& street, double s, double half_width) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  constexpr int kTaps = 11;
  for (int k = 0; k < kTaps; ++k) sum += PointAt(street, s - half_width + 2 * half_width * k / (kTaps - 1));
  return sum / kTaps;
}

// Smooth jitter: a few sinusoids of random frequency and phase, of unit amplitude overall.
struct Jitter {
  double freq[3], phase[3];
  explicit Jitter(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> f(0.3, 1.6), p(0, 2 * M_PI);
    for (int k = 0; k < 3; ++k) freq[k] = f(rng), phase[k] = p(rng);
  }
  double operator()(double t) const {
    double v = 0;
    for (int k = 0; k < 3; ++k) v += std::sin(2 * M_PI * freq[k] * t + phase[k]);
    return v / 3;
  }
};
}  // namespace

Trajectory WalkStreet(const Street& street, const WalkOptions& o, int frames, uint64_t seed) {
  CheckOptionsOrThrow(o, "walk options");
  PDVO_THROW_CHECK(frames > 0, InvalidArgument, "walk: the number of frames must be positive, got " << frames);
  std::mt19937_64 rng(seed ^ 0x9e3779b97f4a7c15ULL);
  const Jitter yaw_jitter(rng), pitch_jitter(rng), roll_jitter(rng);
  const double look_frequency = std::uniform_real_distribution<double>(1 / 30.0, 1 / 12.0)(rng);
  const double look_phase = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
  const double start = street.loop ? 0.0 : 8.0;  // metres into the street
  Trajectory trajectory;
  for (int i = 0; i < frames; ++i) {
    const double t = i / o.fps;
    const double s = start + o.speed * t;
    const Eigen::Vector3d ahead =
        SmoothPointAt(street, s + 1.5, o.corner_smoothing) - SmoothPointAt(street, s - 1.5, o.corner_smoothing);
    const Eigen::Vector3d d = ahead.normalized();
    const Eigen::Vector3d right = RightOf(d);
    const double phase = M_PI * o.step_frequency * t;  // a step per half period of the sway
    Eigen::Vector3d position =
        SmoothPointAt(street, s, o.corner_smoothing) + (o.lateral_offset + o.sway * std::sin(phase)) * right;
    position.y() = -o.eye_height + o.bob * std::cos(2 * phase);
    const double deg = M_PI / 180;
    const double look = o.look_deg * deg * std::sin(2 * M_PI * look_frequency * t + look_phase);
    const double yaw = std::atan2(d.x(), d.z()) + look + o.shake_deg * deg * yaw_jitter(t);
    const double pitch_down = 3.0 * deg + o.shake_deg * deg * pitch_jitter(t);
    const double roll = o.shake_deg * deg * roll_jitter(t) + 0.5 * deg * std::sin(phase);
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY())) *
                                 Eigen::Quaterniond(Eigen::AngleAxisd(-pitch_down, Eigen::Vector3d::UnitX())) *
                                 Eigen::Quaterniond(Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()));
    trajectory.push_back({t, Rigid3d(q, position)});
  }
  return trajectory;
}

}  // namespace pdvo::sim
