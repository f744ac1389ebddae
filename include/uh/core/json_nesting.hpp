#pragma once
/// \file
/// The depth guard of every JSON reader (scene files, the service's and the game's messages): a
/// document nested deeper than kMaxJsonNesting is refused before it is parsed, so that nothing
/// later (a dump, a recursive reader, a destructor) recurses deeply on a file's or a client's input.

#include <string_view>

namespace uh {

/// The deepest nesting of arrays and objects the project's readers accept.
inline constexpr int kMaxJsonNesting = 32;

/// The deepest nesting of arrays and objects in `text`, ignoring brackets inside strings. Linear,
/// no recursion, no allocation; text that is not JSON gets some number (the parser refuses it).
int json_nesting_depth(std::string_view text);

}  // namespace uh
