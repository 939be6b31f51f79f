// Procedural urban streets with exact geometry: the scene (planar facades and ground, non-planar clutter) and a
// hand-held camera walking along it.
//
// World frame: y points down (gravity), the ground is the plane y = 0, so a camera with identity rotation
// looks horizontally along +z. A street is a polyline of straight segments joined at mitred corners (bends
// and turns alternate in direction, so a long street never crosses itself), or a closed loop around a block.
// Along each side stand buildings: front facades set back by varying amounts, joined by side walls where the
// setback changes. The ground is split into road and pavement polygons. Trees (trunk and a crown of spheres),
// bushes, poles and parked cars (ellipsoids) are the non-planar clutter; everything else is sky.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "pdvo/common/trajectory.h"

namespace pdvo::sim {

struct StreetOptions {
  double min_segment_length = 25.0;   // m
  double max_segment_length = 45.0;   // m
  double max_turn_deg = 50.0;         // turn at each corner, degrees (alternating sides)
  double road_width = 7.0;            // m
  double pavement_width = 3.0;        // m
  double min_building_width = 6.0;    // m
  double max_building_width = 16.0;   // m
  double min_building_height = 6.0;   // m
  double max_building_height = 18.0;  // m
  double max_setback = 2.5;           // m, how far a facade may stand back from the pavement
  double tree_spacing = 14.0;         // m, mean distance between trees on each side
  double car_spacing = 18.0;          // m, mean distance between parked cars on each side
  double pole_spacing = 25.0;         // m
  bool loop = false;                  // a closed loop around a block instead of an open street

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("min_segment_length", self.min_segment_length);
    visit("max_segment_length", self.max_segment_length);
    visit("max_turn_deg", self.max_turn_deg);
    visit("road_width", self.road_width);
    visit("pavement_width", self.pavement_width);
    visit("min_building_width", self.min_building_width);
    visit("max_building_width", self.max_building_width);
    visit("min_building_height", self.min_building_height);
    visit("max_building_height", self.max_building_height);
    visit("max_setback", self.max_setback);
    visit("tree_spacing", self.tree_spacing);
    visit("car_spacing", self.car_spacing);
    visit("pole_spacing", self.pole_spacing);
    visit("loop", self.loop);
  }
  bool Check() const;
  bool operator==(const StreetOptions&) const = default;
};

enum class Material { kBrick, kRender, kStone, kRoad, kPavement, kLeaves, kBark, kMetal, kCarPaint };
const char* MaterialName(Material m);

// A planar polygon of the scene. The plane is normal . x + distance = 0, the normal facing the street (or up).
struct WorldPlane {
  int id = 0;
  Material material = Material::kBrick;
  std::vector<Eigen::Vector3d> polygon;  // convex, world frame, metres
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double distance = 0;
  // Texture frame: a point x of the plane has texture coordinates ((x - origin) . axis_u, (x - origin) . axis_v)
  // in metres.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(), axis_u = Eigen::Vector3d::Zero(), axis_v = Eigen::Vector3d::Zero();
  double width = 0, height = 0;  // extent of the polygon in texture coordinates, metres
  uint32_t texture_seed = 0;     // the facade's own windows, doors and signs
  int surface = 0;               // id of the first plane with the same equation (the ground of every segment,
                                 // neighbouring facades on one line): one geometric plane
};

// A non-planar object: an ellipsoid (centre, semi-axes along the world axes rotated by yaw about y) or a
// vertical cylinder (centre at mid-height, radii.x() the radius, radii.y() the half-height).
struct WorldBlob {
  enum class Kind { kEllipsoid, kCylinder };
  int id = 0;
  Kind kind = Kind::kEllipsoid;
  Material material = Material::kLeaves;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d radii = Eigen::Vector3d::Ones();
  double yaw = 0;                                    // radians about the y axis
  Eigen::Vector3d colour = Eigen::Vector3d::Ones();  // BGR in [0, 1]
};

struct Street {
  std::vector<Eigen::Vector3d> centreline;  // points on the ground (y = 0); closed if loop
  bool loop = false;
  std::vector<WorldPlane> planes;  // ids 0..n-1
  std::vector<WorldBlob> blobs;    // ids 0..m-1
  double Length() const;           // of the centreline, metres
};

// A street long enough for a walk of `min_length` metres. The same options and seed give the same street.
Street GenerateStreet(const StreetOptions& options, double min_length, uint64_t seed);

struct WalkOptions {
  double speed = 1.4;           // m/s
  double fps = 30.0;            // frames per second
  double eye_height = 1.6;      // m
  double step_frequency = 1.9;  // Hz
  double bob = 0.025;           // m, vertical step bob
  double sway = 0.03;           // m, lateral sway
  double shake_deg = 0.6;       // degrees, hand-held orientation jitter
  double lateral_offset = 0.0;  // m from the centreline (positive: to the walker's right)
  // Looking around: the gaze turns from the walking direction by up to this many degrees, slowly (a sinusoid of
  // period 12-30 s, random phase), so that some frames see the facades from the front. 0: always ahead.
  double look_deg = 0.0;
  // The path is the street's centreline averaged over this many metres either side, which rounds the corners:
  // a walker turns within a few metres, a car over tens of metres.
  double corner_smoothing = 2.5;

  template <class Self, class V>
  static void Fields(Self& self, V& visit) {
    visit("speed", self.speed);
    visit("fps", self.fps);
    visit("eye_height", self.eye_height);
    visit("step_frequency", self.step_frequency);
    visit("bob", self.bob);
    visit("sway", self.sway);
    visit("shake_deg", self.shake_deg);
    visit("lateral_offset", self.lateral_offset);
    visit("look_deg", self.look_deg);
    visit("corner_smoothing", self.corner_smoothing);
  }
  bool Check() const;
  bool operator==(const WalkOptions&) const = default;
};

// The camera poses (world_from_cam) of `frames` frames walking along the street, turning with it, with step
// bob, sway, smooth hand-held jitter and, if asked, a look around. Timestamps are frame / fps. On a loop the walk
// goes round and round.
Trajectory WalkStreet(const Street& street, const WalkOptions& options, int frames, uint64_t seed);

}  // namespace pdvo::sim
