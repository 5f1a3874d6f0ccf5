#pragma once
// The map file reader's parts in files of their own: the INER section
// (map_file_read_inertial.cpp), read by map_file_read.cpp.
#include "map_file_bytes.hpp"
#include "pvb/slam/core/map.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::slam::mapfile {

/// INER up to its keyframes: the setup and extrinsics into *s, gravity and
/// the map's bias, when it became trusted, into *g (ready).
void read_inertial_head(ByteReader& r, MapSettings* s, MapGravity* g);
/// INER: the map's gravity, each keyframe's state and its link in time.
void read_inertial(ByteReader r, Map* map);
/// WHEL: the wheels' calibration, every value checked.
WheelFit read_wheels(ByteReader r);

}  // namespace pvb::slam::mapfile
