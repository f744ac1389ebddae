// The fast path of the volume query, written once against a lane type and compiled per ISA
// (private to Collette; no include guard on purpose).
//
// Included inside `namespace uh::collette::detail::<isa>` after `using V = <lane type>;` (F4 in
// volume_query.cpp for the baseline ISA, F8 in volume_query_avx2.cpp inside a region compiled for
// AVX2, F16 in volume_query_avx512.cpp inside a region compiled for AVX-512) and
// `template <int W> using BlockLanes = <lanes for a block of W children>;` (V, or narrower lanes
// when a block is narrower than V), so that each ISA gets its own copy of these functions under its
// own names. It includes nothing itself: the including file includes volume_traversal.hpp and the
// lane headers first.
//
// Every lane operation is the scalar kernel's operation in the scalar kernel's order, so each pair
// is bit for bit what the reference path computes, at any width; pairs are found, stored and summed
// in the reference path's order, so the totals are identical too.

// bit j set when lane j of the (x, y, z, r) lanes overlaps the sphere (px, py, pz, pr)
template <int W>
[[gnu::always_inline]] inline std::uint32_t overlap_mask(const float* x, const float* y, const float* z,
                                                         const float* r, float px, float py, float pz,
                                                         float pr) {
  using L = BlockLanes<W>;
  const L bx = L::set1(px), by = L::set1(py), bz = L::set1(pz), br = L::set1(pr);
  std::uint32_t hits = 0;
  for (int k = 0; k < W; k += L::kWidth) {
    const L dx = bx - L::load(x + k), dy = by - L::load(y + k), dz = bz - L::load(z + k);
    const L rs = br + L::load(r + k);
    hits |= bits((dx * dx + dy * dy) + dz * dz < rs * rs) << k;
  }
  return hits;
}

// row j of a visit's child-pair mask: child j of B (moved, in tb) against A's children (block ab),
// at bits 8 j + k
template <int WA, int WB>
[[gnu::always_inline]] inline std::uint64_t row_mask(const float* ab, const float* tb, int j, float sm) {
  return static_cast<std::uint64_t>(overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, tb[j], tb[WB + j],
                                                     tb[2 * WB + j], tb[3 * WB + j] + sm))
         << (8 * j);
}

// rows j and j + 1 of a visit's child-pair mask in one group of lanes, when a group is two rows
// wide (16 lanes and A's blocks 8 wide, or 8 lanes and 4 wide) and B's block is 8 wide: A's
// children twice, child j of B against the first half of the lanes, child j + 1 against the second.
// bx .. br: B's moved children (eight lanes, radius plus the search margin), spread by one permute
// each. The operations of row_mask, so the bits are the same.
template <int WA, typename L = V>  // L: V, named so that only widths with spread_pair() compile it
[[gnu::always_inline]] inline std::uint64_t row_pair_mask(const float* ab, BlockLanes<8> bx, BlockLanes<8> by,
                                                          BlockLanes<8> bz, BlockLanes<8> br, int j) {
  static_assert(2 * WA == L::kWidth);
  const L dx = L::spread_pair(bx, j) - L::load_twice(ab);
  const L dy = L::spread_pair(by, j) - L::load_twice(ab + WA);
  const L dz = L::spread_pair(bz, j) - L::load_twice(ab + 2 * WA);
  const L rs = L::spread_pair(br, j) + L::load_twice(ab + 3 * WA);
  const std::uint64_t m = bits((dx * dx + dy * dy) + dz * dz < rs * rs);
  // row j + 1 from bit WA to bit 8 (nothing moves when WA is 8)
  return ((m & ((1u << WA) - 1u)) | ((m >> WA) << 8)) << (8 * j);
}

// B's children of block kb moved into A's frame: t[0..W) x, t[W..2W) y, t[2W..3W) z, t[3W..4W) r
// (the association of Traversal::transform_block, so both paths move a sphere to the same place)
template <int W>
[[gnu::always_inline]] inline void transform_block(const Traversal& t, std::int32_t kb, float* out) {
  using L = BlockLanes<W>;
  const float* src = t.b.bounds + static_cast<std::size_t>(kb) * 4 * W;
  const FloatTransform& f = t.xf;
  for (int k = 0; k < W; k += L::kWidth) {
    const L x = L::load(src + k), y = L::load(src + W + k), z = L::load(src + 2 * W + k);
    store(out + k,
          (L::set1(f.r[0][0]) * x + L::set1(f.r[0][1]) * y) + (L::set1(f.r[0][2]) * z + L::set1(f.t[0])));
    store(out + W + k,
          (L::set1(f.r[1][0]) * x + L::set1(f.r[1][1]) * y) + (L::set1(f.r[1][2]) * z + L::set1(f.t[1])));
    store(out + 2 * W + k,
          (L::set1(f.r[2][0]) * x + L::set1(f.r[2][1]) * y) + (L::set1(f.r[2][2]) * z + L::set1(f.t[2])));
    store(out + 3 * W + k, L::load(src + 3 * W + k));
  }
}

// B's block kb moved into A's frame: moved by the first visit of this run that needs it, then read
// from the traversal's MovedBlocks (the same lanes, bit for bit)
template <int W>
[[gnu::always_inline]] inline const float* moved_block(const Traversal& t, float* moved, std::uint32_t* stamp,
                                                       std::uint32_t run, std::int32_t kb) {
  float* out = moved + static_cast<std::size_t>(kb) * 4 * W;
  if (stamp[kb] != run) {
    transform_block<W>(t, kb, out);
    stamp[kb] = run;
  }
  return out;
}

// Lanes i .. i + V::kWidth - 1 of the batch through the lens kernel into `out` (lanes from 0);
// returns the lanes that overlap (bit j: lane i + j) and, in `near`, those apart by less than
// `margin` (only when margin > 0). The operations of uh::sphere_overlap<float>, branch by branch,
// with the branches blended by masks.
[[gnu::always_inline]] inline std::uint32_t lens_lanes(const LeafBatch& b, int i, float margin,
                                                       LensLanes& out, std::uint32_t& near) {
  const V ax = V::load(b.ax + i), ay = V::load(b.ay + i), az = V::load(b.az + i), ar = V::load(b.ar + i);
  const V bx = V::load(b.bx + i), by = V::load(b.by + i), bz = V::load(b.bz + i), br = V::load(b.br + i);
  const V zero = V::zero();
  const V dx = bx - ax, dy = by - ay, dz = bz - az;
  const V d = sqrt((dx * dx + dy * dy) + dz * dz);
  const V sum = ar + br;
  const auto touching = d < sum;  // masks: V, or M16 with sixteen lanes
  const V delta = ar - br;
  const V rmin = min(br, ar);  // std::min(ar, br): br < ar ? br : ar
  const V contained = ((V::set1(kFourThirdsPiF) * rmin) * rmin) * rmin;
  const auto containment = (d <= abs(delta)) | (d < V::set1(std::numeric_limits<float>::min()));
  // the lens (garbage in lanes that are apart or contained; blended away below)
  const V s = sum - d;
  const V half_inv_d = V::set1(0.5f) / d;
  const V p1 = (d - delta) * half_inv_d;
  const V p2 = (d + delta) * half_inv_d;
  const V three = V::set1(3.f);
  const V t1 = (p1 * p1) * (three * ar - s * p1);
  const V t2 = (p2 * p2) * (three * br - s * p2);
  const V t12 = t1 + t2;
  const V lens = min(contained, ((V::set1(kPiThirdF) * s) * s) * t12);
  const V lens_area = (((V::set1(kPiF) * s) * (sum + d)) * p1) * p2;
  const V lens_offset = (d * t2) / t12;
  const V contained_offset = andnot(ar <= br, d);  // ar <= br ? 0 : d
  const V volume = touching & ((containment & contained) | andnot(containment, lens));
  const V area = andnot(containment, touching) & lens_area;
  const V offset = (containment & contained_offset) | andnot(containment, lens_offset);
  const V inv = (d > zero) & (V::set1(1.f) / d);
  const V nx = dx * inv, ny = dy * inv, nz = dz * inv;
  store(out.volume, volume);
  store(out.area, area);
  store(out.nx, nx);
  store(out.ny, ny);
  store(out.nz, nz);
  store(out.cx, ax + nx * offset);
  store(out.cy, ay + ny * offset);
  store(out.cz, az + nz * offset);
  const auto overlap = volume > zero;
  near = margin > 0.f ? bits(andnot(overlap, d < sum + V::set1(margin))) : 0u;
  return bits(overlap);
}

// Evaluates the batched leaf pairs, in the order they were added (so pairs are stored and summed
// exactly as the reference path would), and empties the batch.
inline void flush(Traversal& t) {
  LeafBatch& lb = *t.batch;
  lb.pad();
  LensLanes lanes;
  alignas(32) float rows[16 * 8];  // lane j's pair: rows[8 j .. 8 j + 8) (PairSums' order)
  static_assert(offsetof(LensLanes, area) == offsetof(LensLanes, volume) + 16 * sizeof(float) &&
                offsetof(LensLanes, cz) == offsetof(LensLanes, volume) + 7 * 16 * sizeof(float) &&
                offsetof(LensLanes, nx) == offsetof(LensLanes, volume) + 2 * 16 * sizeof(float));
  PairSums sums(t.sum);
  constexpr int kGroup = V::kWidth;
  static_assert(kGroup <= LeafBatch::kPad);
  for (int i = 0; i < lb.count; i += kGroup) {
    std::uint32_t near_lanes = 0;
    const std::uint32_t hits = lens_lanes(lb, i, t.margin, lanes, near_lanes);
    const std::uint32_t valid = lb.count - i >= kGroup ? (1u << kGroup) - 1u : (1u << (lb.count - i)) - 1u;
    std::uint32_t todo = (hits | near_lanes) & valid;
    if (todo) V::to_rows(lanes.volume, 16, rows);
    if (hits == (1u << kGroup) - 1u && t.stored + kGroup <= t.capacity) {
      // every lane overlaps (most groups): the pairs in lane order, without scanning the bits
      for (int j = 0; j < kGroup; ++j) t.add_overlap_row(sums, rows + 8 * j, lb.leaf_a[i + j], lb.leaf_b[i + j]);
      continue;
    }
    while (todo) {
      const int j = std::countr_zero(todo);
      todo &= todo - 1u;
      const int k = i + j;
      if ((hits >> j) & 1u) {
        t.add_overlap_row(sums, rows + 8 * j, lb.leaf_a[k], lb.leaf_b[k]);
      } else {
        const float dx = lb.bx[k] - lb.ax[k], dy = lb.by[k] - lb.ay[k], dz = lb.bz[k] - lb.az[k];
        t.add_near_pair(dx, dy, dz, std::sqrt(dx * dx + dy * dy + dz * dz), lb.ax[k], lb.ay[k], lb.az[k],
                        lb.ar[k], lb.leaf_a[k], lb.leaf_b[k]);
      }
    }
  }
  sums.store(t.sum);
  lb.count = 0;
}

// The fast traversal: the same node pairs in the same order as the reference path, and the same
// leaf pairs, but each visit first tests all its child pairs into one mask (8 bits per child of
// B), then appends the leaf pairs among the hits to the batch and pushes the rest, in two loops
// without data-dependent branches in their bodies (the reference's branch per hit mispredicted
// about once per hit). Leaf pairs are evaluated a SIMD group at a time by flush(). Within a visit,
// both the leaf pairs and the pushes come in the reference's (child of B, child of A) order, so
// pairs are found, stored and summed in the same order: the results are identical.
// Runs until the stack is empty or holds `stop_at` entries (expand()), then evaluates the batch.
template <int WA, int WB>
void run_fast(Traversal& t, std::size_t stop_at) {
  static_assert(WA <= 8 && WB <= 8);
  LeafBatch& lb = *t.batch;
  float* const moved = t.moved->data();
  std::uint32_t* const stamp = t.moved->stamp.data();
  const std::uint32_t run = t.moved->run;
  const SphereTree::Blocks& a = t.a;
  const SphereTree::Blocks& b = t.b;
  const float sm = t.search_margin;
  // the stack's top, the batch's count and the statistics in locals (registers) during the loop:
  // in memory, every push and every appended pair would store them again, since the compiler cannot
  // tell them apart from the entries and pairs being written
  VolumeQuery::StackEntry* stack = t.stack->data();
  std::size_t top = t.top, room = t.stack->size();
  int count = lb.count;
  std::int64_t visited = 0, leaf_tests = 0;
  const auto push = [&](std::int32_t ia, std::int32_t ib, float ax, float ay, float az, float ar, float bx,
                        float by, float bz, float br) __attribute__((always_inline)) {
    t.prefetch_pair<WA, WB>(ia, ib);
    store_entry(stack + top++, ia, ib, ax, ay, az, ar, bx, by, bz, br, VolumeQuery::kRowsUnknown);
  };
  while (top > 0 && top < stop_at) {
    if (count > LeafBatch::kCapacity - WA * WB) {
      lb.count = count;
      flush(t);
      count = 0;
    }
    const VolumeQuery::StackEntry e = load_entry(stack + --top);
    ++visited;
    if (room - top < static_cast<std::size_t>(WA * WB)) {
      t.top = top;
      t.reserve_stack(static_cast<std::size_t>(WA * WB));
      stack = t.stack->data();
      room = t.stack->size();
    }
    if (e.a < 0) {
      // A is a leaf: B's children against it
      const Sphere& s = t.leaves_a[~e.a];
      const float* tb = moved_block<WB>(t, moved, stamp, run, e.b);
      const std::uint32_t leaf_b = b.leaf_mask[e.b];
      const std::uint32_t hits =
          overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, s.x, s.y, s.z, s.radius + sm) &
          ((1u << b.count[e.b]) - 1u);
      leaf_tests += kBitCount[leaf_b];
      const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
      for (std::uint32_t m = hits & leaf_b; m; m &= m - 1u) {
        const int j = std::countr_zero(m);
        lb.set(count++, s.x, s.y, s.z, s.radius, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j], ~e.a, ~cb[j]);
      }
      for (std::uint32_t m = hits & ~leaf_b; m; m &= m - 1u) {
        const int j = std::countr_zero(m);
        push(e.a, cb[j], e.ax, e.ay, e.az, e.ar, tb[j], tb[WB + j], tb[2 * WB + j], tb[3 * WB + j]);
      }
      continue;
    }
    const float* ab = a.bounds + static_cast<std::size_t>(e.a) * 4 * WA;
    const std::int32_t* ca = a.child + static_cast<std::size_t>(e.a) * WA;
    const std::uint32_t leaf_a = a.leaf_mask[e.a];
    if (e.b < 0) {
      // B is a leaf: A's children against it (padding lanes of A never overlap)
      const std::uint32_t hits =
          overlap_mask<WA>(ab, ab + WA, ab + 2 * WA, ab + 3 * WA, e.bx, e.by, e.bz, e.br + sm);
      leaf_tests += kBitCount[leaf_a];
      for (std::uint32_t m = hits & leaf_a; m; m &= m - 1u) {
        const int k = std::countr_zero(m);
        lb.set(count++, ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by, e.bz, e.br, ~ca[k], ~e.b);
      }
      for (std::uint32_t m = hits & ~leaf_a; m; m &= m - 1u) {
        const int k = std::countr_zero(m);
        push(ca[k], e.b, ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], e.bx, e.by, e.bz, e.br);
      }
      continue;
    }
    // both inner: every child of B (moved once) against all children of A; bit 8 j + k of the mask
    // is child j of B against child k of A
    const float* tb = moved_block<WB>(t, moved, stamp, run, e.b);
    const std::uint32_t leaf_b = b.leaf_mask[e.b];
    const std::int32_t* cb = b.child + static_cast<std::size_t>(e.b) * WB;
    leaf_tests += kBitCount[leaf_a] * kBitCount[leaf_b];
    // only B's children that reach A's node sphere can reach a leaf below A: the rows of the others
    // (a third to a half) are dropped. The pair's push tested them (e.rows) unless it came from
    // elsewhere. When a row is one group of lanes (or two rows are, with sixteen lanes), every row is
    // tested in a loop of fixed length (no branch to mispredict) and the mask drops rows afterwards;
    // with eight lanes, the loop runs over the first four kept rows; narrower lanes test only the
    // rows kept.
    const std::uint32_t rows =
        e.rows != VolumeQuery::kRowsUnknown
            ? e.rows
            : overlap_mask<WB>(tb, tb + WB, tb + 2 * WB, tb + 3 * WB, e.ax, e.ay, e.az, e.ar + sm) &
                  ((1u << b.count[e.b]) - 1u);
    std::uint64_t hits = 0;
    if constexpr (2 * WA == V::kWidth && WB == 8) {
      using B8 = BlockLanes<8>;
      const B8 bx = B8::load(tb), by = B8::load(tb + 8), bz = B8::load(tb + 16);
      const B8 br = B8::load(tb + 24) + B8::set1(sm);
      for (int j = 0; j < WB; j += 2) hits |= row_pair_mask<WA>(ab, bx, by, bz, br, j);
      hits &= kByteMask[rows];
    } else if constexpr (WA <= V::kWidth) {
      // the first four kept rows in a loop of fixed length (the row indices from a table), the
      // others after, when there are more than four (about a quarter of the visits on the deep
      // random poses): half the row tests of a loop over all eight for the other three quarters,
      // and no branch per row
      std::uint32_t list = kRowList[rows];
      for (int i = 0; i < 4; ++i, list >>= 8) hits |= row_mask<WA, WB>(ab, tb, static_cast<int>(list & 0xffu), sm);
      if (kBitCount[rows] > 4) {
        std::uint32_t rest = rows;
        for (int i = 0; i < 4; ++i) rest &= rest - 1u;
        list = kRowList[rest];
        for (int i = 0; i < 4; ++i, list >>= 8) hits |= row_mask<WA, WB>(ab, tb, static_cast<int>(list & 0xffu), sm);
      }
      hits &= kByteMask[rows];
    } else {
      for (std::uint32_t m = rows; m; m &= m - 1u) hits |= row_mask<WA, WB>(ab, tb, std::countr_zero(m), sm);
    }
    const std::uint64_t leaf_pairs =
        hits & kByteMask[leaf_b] & (static_cast<std::uint64_t>(leaf_a) * 0x0101010101010101ull);
    for (std::uint64_t m = leaf_pairs; m; m &= m - 1u) {
      const int bit = std::countr_zero(m), j = bit >> 3, k = bit & 7;
      lb.set(count++, ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j], tb[WB + j], tb[2 * WB + j],
             tb[3 * WB + j], ~ca[k], ~cb[j]);
    }
    for (std::uint64_t m = hits & ~leaf_pairs; m; m &= m - 1u) {
      const int bit = std::countr_zero(m), j = bit >> 3, k = bit & 7;
      if (ca[k] >= 0 && cb[j] >= 0) {
        // two inner nodes: their visit's rows tested now (B's child moved into A's frame now rather
        // than at the visit), and the pair pushed only when a row is left, without a branch: about
        // three in ten such pairs have none (their visit would find nothing)
        const float* tj = moved_block<WB>(t, moved, stamp, run, cb[j]);
        const std::uint32_t r = overlap_mask<WB>(tj, tj + WB, tj + 2 * WB, tj + 3 * WB, ab[k], ab[WA + k],
                                                 ab[2 * WA + k], ab[3 * WA + k] + sm) &
                                ((1u << b.count[cb[j]]) - 1u);
        const char* pa = reinterpret_cast<const char*>(a.bounds + static_cast<std::size_t>(ca[k]) * 4 * WA);
        prefetch(pa);
        if constexpr (WA == 8) prefetch(pa + 64);
        store_entry(stack + top, ca[k], cb[j], ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j],
                    tb[WB + j], tb[2 * WB + j], tb[3 * WB + j], r);
        top += r != 0 ? 1 : 0;
      } else {
        push(ca[k], cb[j], ab[k], ab[WA + k], ab[2 * WA + k], ab[3 * WA + k], tb[j], tb[WB + j], tb[2 * WB + j],
             tb[3 * WB + j]);
      }
    }
  }
  t.top = top;
  t.visited += visited;
  t.leaf_tests += leaf_tests;
  lb.count = count;
  flush(t);
}

// one loop per pair of block widths (trees built with arity <= 4 and > 4 can meet)
void run_until(Traversal& t, std::size_t stop_at) {
  const bool wide_a = t.a.width != 4, wide_b = t.b.width != 4;
  if (!wide_a)
    wide_b ? run_fast<4, 8>(t, stop_at) : run_fast<4, 4>(t, stop_at);
  else
    wide_b ? run_fast<8, 8>(t, stop_at) : run_fast<8, 4>(t, stop_at);
}

void run_fast(Traversal& t) { run_until(t, std::numeric_limits<std::size_t>::max()); }

void expand(Traversal& t, std::size_t entries) { run_until(t, entries); }
