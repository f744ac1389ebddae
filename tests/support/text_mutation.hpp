#pragma once
// Random edits of a valid text, for the property tests of the parsers: "any mutation either
// parses or gives an error naming the source".

#include <random>
#include <string>
#include <string_view>

namespace uh::test {

/// `text` after 1 to 4 random single-character insertions, deletions or replacements drawn from
/// `alphabet`.
inline std::string mutate_text(std::string text, std::string_view alphabet, std::mt19937& rng) {
  const int edits = 1 + static_cast<int>(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const std::size_t pos = rng() % (text.size() + 1);
    const char c = alphabet[rng() % alphabet.size()];
    switch (rng() % 3) {
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
