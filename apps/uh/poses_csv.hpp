#pragma once
/// \file
/// Reads the pose list of `uh query`: a CSV with the header `id,tx,ty,tz,qw,qx,qy,qz` (any column
/// order; extra columns are ignored; '#' comment lines and blank lines skipped; read by
/// uh::CsvReader, whose errors name the file, line and column). Each row is the pose of B's mesh frame in A's mesh frame, in
/// the meshes' own units, quaternion w first (normalised on read; a zero quaternion is an error).

#include <filesystem>
#include <string>
#include <vector>

#include "uh/core/math.hpp"
#include "uh/core/result.hpp"

namespace uh::cli {

struct PoseRow {
  std::string id;
  Pose b_in_a{};
};

Result<std::vector<PoseRow>> read_poses_csv(const std::filesystem::path& path);

}  // namespace uh::cli
