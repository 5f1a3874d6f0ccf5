#pragma once
// PLY files for coloured clouds: binary little endian, one `vertex` element
// with properties x y z (float) and red green blue (uchar), which
// CloudCompare, MeshLab and Open3D read.
#include <cstddef>
#include <functional>
#include <string>

#include "pvb/slam/dense/point_cloud.hpp"

namespace pvb::slam::dense {

/// Writes the cloud; throws pvb::IoError when the file cannot be written.
void write_ply(const std::string& path, const PointCloud& cloud);

/// A cloud handed over in pieces: it calls the sink with each piece in order.
using CloudChunks = std::function<void(const std::function<void(const PointCloud&)>&)>;

/// Writes a cloud of `vertices` points that `chunks` hands over piece by
/// piece, holding one piece at a time (a map larger than memory streams to
/// disk).  Throws pvb::IoError when the file cannot be written or the
/// pieces do not add up to `vertices` (the file is then not made).
void write_ply(const std::string& path, std::size_t vertices, const CloudChunks& chunks);

/// What read_ply() left out.
struct PlyReadStats {
  std::size_t non_finite_dropped = 0;  ///< vertices with a NaN or infinite coordinate
};

/// Reads a PLY file as write_ply() writes it (binary_little_endian 1.0, a
/// vertex element whose properties are float x y z and uchar red green blue
/// in that order; comments allowed, no other elements).  The body must hold
/// exactly the vertices the header announces (checked against the file's
/// size before anything is allocated).  Vertices with a NaN or infinite
/// coordinate are left out and counted in `stats`.  Throws pvb::IoError
/// naming the file and the header line that is not understood, or a body
/// of the wrong size.
PointCloud read_ply(const std::string& path, PlyReadStats* stats = nullptr);

}  // namespace pvb::slam::dense
