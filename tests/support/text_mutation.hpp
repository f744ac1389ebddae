#pragma once
// Random edits of a valid text, for the property tests of the parsers: "any mutation either
// parses or gives an error naming the source".

#include <string>
#include <string_view>

#include "uh/core/split_mix.hpp"

namespace uh::test {

/// `text` after 1 to 4 random single-character insertions, deletions or replacements drawn from
/// `alphabet`.
inline std::string mutate_text(std::string text, std::string_view alphabet, core::SplitMix64& rng) {
  const int edits = 1 + static_cast<int>(rng.next() % 4);
  for (int e = 0; e < edits; ++e) {
    const std::size_t pos = rng.next() % (text.size() + 1);
    const char c = alphabet[rng.next() % alphabet.size()];
    switch (rng.next() % 3) {
      case 0:
        text.insert(pos, 1, c);
        break;
      case 1:
        if (pos < text.size()) text.erase(pos, 1);
        break;
      default:
        if (pos < text.size()) text[pos] = c;
        break;
    }
  }
  return text;
}

}  // namespace uh::test
