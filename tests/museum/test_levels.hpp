#pragma once
// Small levels that isolate one rule at a time: an open hall, or two rooms joined by a doorway.

#include "uh/museum/level.hpp"

namespace uh::museum::test {

// a 20 m x 10 m hall, the entrance and the table west, `cases` cases along y = 5 from x = 4 every
// 0.5 m (so that several are within reach at once) and no guards unless a test adds them
inline Level open_hall(int cases = 2) {
  Level level;
  level.name = "open hall";
  level.rooms = {{"hall", {0.0, 0.0}, {20.0, 10.0}}};
  level.entrance = {1.0, 1.0};
  level.table = {2.0, 1.0};
  for (int c = 0; c < cases; ++c) level.cases.push_back({{4.0 + 0.5 * c, 5.0}});
  level.artifact_kinds = {"amphora", "bowl", "coin"};
  level.target_count = cases / 2;
  return level;
}

// two 9 m x 10 m rooms with a 1 m wall at x = 9..10 and a 1 m doorway at y = 4.5..5.5
inline Level two_rooms() {
  Level level = open_hall();
  level.name = "two rooms";
  level.rooms = {{"west", {0.0, 0.0}, {9.0, 10.0}},
                 {"door", {8.5, 4.5}, {10.5, 5.5}},
                 {"east", {10.0, 0.0}, {19.0, 10.0}}};
  return level;
}

}  // namespace uh::museum::test
