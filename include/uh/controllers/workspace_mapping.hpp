#pragma once
/// \file
/// WorkspaceMapping: described by the scene (uh/scene/workspace_mapping.hpp), used by the controllers.

#include "uh/scene/workspace_mapping.hpp"

namespace uh::controllers {
using uh::scene::WorkspaceMapping;
}  // namespace uh::controllers
