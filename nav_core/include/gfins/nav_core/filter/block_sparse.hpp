// The filter's 18×18 matrices as 6×6 blocks of 3×3 (one block per error quantity of
// measurement.hpp: φ, δr, δv, δω, δβ_ω̇, δβ_f), and the one product the propagation needs,
// C = A B with A block-sparse: only the blocks of A that its structural mask names are read.
//
// Why: the process model F of the filter has 8 non-zero blocks of 36 (error_state_filter.hpp
// says which), its transition matrix Φ = I + F h + F² h²/2 has 18, and the dense products of
// P ← Φ P Φᵀ + Q_d cost about 29 000 multiply-accumulates per propagation where the structure
// needs about 11 000. The mask is structural (which blocks the model can fill), never a test of
// the values, so the cost of a propagation does not depend on the state (at rest, level, most of
// F's entries are zero; in a turn they are not). One plain kernel for every product also keeps
// the flash of the Cortex-M4F image below that of a template instantiation per product shape.
#pragma once

#include <cstdint>

#include "gfins/nav_core/filter/measurement.hpp"

namespace gfins::nav::blocks {

inline constexpr int kBlock = 3;
inline constexpr int kBlocks = filt_idx::kStates / kBlock;  // 6
static_assert(kBlocks * kBlock == filt_idx::kStates, "the state is a whole number of 3-blocks");

/// Bit r·6 + c set: block (r, c) may be non-zero.
using Mask = std::uint64_t;

constexpr Mask bit(int r, int c) { return Mask{1} << (r * kBlocks + c); }
constexpr bool has(Mask m, int r, int c) { return (m & bit(r, c)) != 0; }

constexpr Mask identity() {
  Mask m = 0;
  for (int i = 0; i < kBlocks; ++i) m |= bit(i, i);
  return m;
}

/// The blocks A B can fill when A and B fill those of their masks.
constexpr Mask product(Mask a, Mask b) {
  Mask m = 0;
  for (int r = 0; r < kBlocks; ++r) {
    for (int c = 0; c < kBlocks; ++c) {
      for (int k = 0; k < kBlocks; ++k) {
        if (has(a, r, k) && has(b, k, c)) m |= bit(r, c);
      }
    }
  }
  return m;
}

/// Number of blocks a mask names (the cost of a product is that times 6 × 27 multiply-adds).
constexpr int count(Mask m) {
  int n = 0;
  for (; m != 0; m &= m - 1) ++n;
  return n;
}

/// C = A B for column-major 18×18 matrices (Eigen's default storage), reading only the blocks of
/// A in `a_mask` (the others are taken as zero whatever they hold). C must not alias A or B.
template <typename T>
void multiply(Mask a_mask, const T* a, const T* b, T* c) {
  constexpr int n = filt_idx::kStates;
  for (int i = 0; i < n * n; ++i) c[i] = T(0);
  for (int rb = 0; rb < kBlocks; ++rb) {
    for (int kb = 0; kb < kBlocks; ++kb) {
      if (!has(a_mask, rb, kb)) continue;
      // The 3×3 block of A in registers, then every column of B's three rows through it.
      T blk[kBlock][kBlock];
      for (int i = 0; i < kBlock; ++i) {
        for (int k = 0; k < kBlock; ++k) blk[i][k] = a[(rb * kBlock + i) + n * (kb * kBlock + k)];
      }
      for (int j = 0; j < n; ++j) {
        const T* bj = b + n * j + kb * kBlock;
        T* cj = c + n * j + rb * kBlock;
        for (int i = 0; i < kBlock; ++i) {
          cj[i] += blk[i][0] * bj[0] + blk[i][1] * bj[1] + blk[i][2] * bj[2];
        }
      }
    }
  }
}

}  // namespace gfins::nav::blocks
