#pragma once
/// \file
/// A software-rendered PNG picture of a sphere packing (like the paper's bunny figures). Part of
/// builds with libpng only: the Windows build leaves it out (the uh program is its only user).

#include <filesystem>
#include <vector>

#include "uh/core/contact.hpp"
#include "uh/core/result.hpp"

namespace uh::collette {

/// How write_packing_preview() draws (Box2D-style aggregate).
struct PreviewOptions {
  int width = 800;        ///< pixels
  int height = 800;       ///< pixels
  /// Cut by a plane through the centre of the packing facing the camera and drop the near half;
  /// spheres crossing the plane show as flat discs (their cross-sections).
  bool section = false;
  /// View direction from the camera, in the mesh frame; the default is a fixed 3/4 view
  /// (camera in front, right and above, +y up).
  double view_azimuth_deg = 35.0;
  double view_elevation_deg = 25.0;
};

/// Renders the spheres orthographically (shaded, coloured by radius: blue small to yellow large)
/// and writes an 8-bit RGB PNG. Writes to a temporary file in the same directory and renames it,
/// so an existing file survives a failure. Not real-time safe; any thread.
Status write_packing_preview(const std::vector<Sphere>& spheres, const std::filesystem::path& png,
                             const PreviewOptions& options = {});

}  // namespace uh::collette
