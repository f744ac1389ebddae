#pragma once
/// \file
/// Which of an artifact's two pieces is meant: the genuine one or its forgery. Here, with the
/// rules, so that the messages that name it need not link the artifacts' meshes (uh::museum_artifacts).

#include <cstdint>

namespace uh::museum {

enum class Piece : std::uint8_t { genuine, forgery };
inline const char* to_string(Piece piece) { return piece == Piece::genuine ? "genuine" : "forgery"; }

}  // namespace uh::museum
