#include "chapters/14_every_lane/lane_scatter.hpp"

#include <algorithm>
#include <iomanip>
#include <sstream>

namespace fem::ch14 {

namespace {

// Asks for the lines elements [first, last) will read and write: their blocks of A (72 bytes,
// two lines where a block straddles one), and x, v and b at their corners. Write intent for
// what the scatter adds into. Always inlined: as a function of its own, GCC 12 took it for one
// without effects (a prefetch changes no value) and dropped its calls, prefetches and all (the
// object held no prefetch instruction, and the beam's pass ran as fast as chapter 12's).
EIGEN_ALWAYS_INLINE void fetch_ahead(int first, int last, const std::vector<Eigen::Vector4i>& tets,
                                     const std::vector<std::array<int, 16>>& element_blocks,
                                     const State& state, const ch08::System& system) {
  for (int e = first; e < last; ++e) {
    for (const int k : element_blocks[e]) {
      const double* block = system.A.blocks[k].data();
      __builtin_prefetch(block, 1);
      __builtin_prefetch(block + 8, 1);
    }
    for (int a = 0; a < 4; ++a) {
      const int node = 3 * tets[e][a];
      __builtin_prefetch(state.x.data() + node);
      __builtin_prefetch(state.v.data() + node);
      __builtin_prefetch(system.b.data() + node, 1);
    }
  }
}

#if defined(EIGEN_VECTORIZE_AVX512)
// The scatter at the vector width (AVX-512: a block's first eight entries are one register).
// Chapter 12's scatter takes each lane's nine entries of a block one by one, strided across
// the batch's registers, and adds them one by one: for a pair of corners and its two blocks,
// 27 scalar loads and 18 stores. Here each pair's first eight registers of lanes are
// transposed once a batch into one register a lane (24 shuffles for 8 x 8 doubles); a block
// is then added by one load, one addition and one store, and its ninth entry alone. The same
// additions into the same entries in the same order (lane by lane, as chapter 12): the same bits.
using Eigen::internal::Packet8d;

// Per lane and pair, K(0,0) .. K(2,1) in row-major order (K(2,2) stays in the terms).
struct LaneMajorBlocks {
  Packet8d rows[ch12::kLanes][10];
};

// out[l] = (in[0][l], ..., in[7][l]): pairs of rows interleaved, then 128-bit and 256-bit
// halves exchanged (unpacklo/hi and shuffle_f64x2; Eigen's own ptranspose of a
// PacketBlock<Packet8d, 8> takes sixteen more extracts).
void transpose8(const Packet8d (&in)[8], Packet8d (&out)[8]) {
  Packet8d t[8], u[8];
  for (int k = 0; k < 4; ++k) {
    t[2 * k] = _mm512_unpacklo_pd(in[2 * k], in[2 * k + 1]);
    t[2 * k + 1] = _mm512_unpackhi_pd(in[2 * k], in[2 * k + 1]);
  }
  for (int h = 0; h < 2; ++h)  // rows 0-3, rows 4-7
    for (int odd = 0; odd < 2; ++odd) {
      const Packet8d lo = t[4 * h + odd], hi = t[4 * h + odd + 2];
      u[4 * h + 2 * odd] = _mm512_shuffle_f64x2(lo, hi, 0x88);      // columns odd, odd + 4
      u[4 * h + 2 * odd + 1] = _mm512_shuffle_f64x2(lo, hi, 0xDD);  // columns odd + 2, odd + 6
    }
  // u[4 h + q] holds columns c(q) and c(q) + 4 of rows 4 h .. 4 h + 3, c = 0, 2, 1, 3.
  constexpr int column[4] = {0, 2, 1, 3};
  for (int q = 0; q < 4; ++q) {
    out[column[q]] = _mm512_shuffle_f64x2(u[q], u[4 + q], 0x88);
    out[column[q] + 4] = _mm512_shuffle_f64x2(u[q], u[4 + q], 0xDD);
  }
}

void to_lane_major(const ch12::BatchTerms& terms, LaneMajorBlocks& out) {
  using namespace Eigen::internal;
  for (int p = 0; p < 10; ++p) {
    Packet8d rows[8], lanes[8];
    for (int r = 0; r < 8; ++r) rows[r] = pload<Packet8d>(terms.K[p][r / 3][r % 3].v);
    transpose8(rows, lanes);
    for (int l = 0; l < ch12::kLanes; ++l) out.rows[l][p] = lanes[l];
  }
}

// `entries` (row-major) added into a block's first eight (column-major, Eigen's default) and
// the ninth: K into the block (a, c) through a permutation, K^T into (c, a) as it is.
EIGEN_ALWAYS_INLINE void add_block(double* block, const Packet8d& entries, double ninth) {
  using namespace Eigen::internal;
  pstoreu(block, padd(ploadu<Packet8d>(block), entries));
  block[8] += ninth;
}

void scatter_lane(const ch12::BatchTerms& terms, const LaneMajorBlocks& k, int lane,
                  const Eigen::Vector4i& t, const std::array<int, 16>& blocks,
                  ch07::BlockSparseMatrix& A, Eigen::VectorXd& b) {
  // Column-major entry m = 3 j + i of K is row-major entry 3 i + j.
  const __m512i to_columns = _mm512_set_epi64(5, 2, 7, 4, 1, 6, 3, 0);
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) b[3 * t[a] + i] += terms.rhs[i][a].v[lane];
  for (int p = 0; p < 10; ++p) {
    const int a = ch08::kUpperPairs[p][0], c = ch08::kUpperPairs[p][1];
    const double ninth = terms.K[p][2][2].v[lane];
    add_block(A.blocks[blocks[4 * a + c]].data(),
              _mm512_permutexvar_pd(to_columns, k.rows[lane][p]), ninth);
    if (a != c) add_block(A.blocks[blocks[4 * c + a]].data(), k.rows[lane][p], ninth);
  }
}

void scatter_batch(const ch12::BatchTerms& terms, int first, int count,
                   const std::vector<Eigen::Vector4i>& tets,
                   const std::vector<std::array<int, 16>>& element_blocks, ch08::System& system) {
  LaneMajorBlocks k;
  to_lane_major(terms, k);
  for (int l = 0; l < count; ++l)
    scatter_lane(terms, k, l, tets[first + l], element_blocks[first + l], system.A, system.b);
}
#else
// Chapter 12's scatter, lane by lane, where a register holds fewer than eight doubles.
void scatter_batch(const ch12::BatchTerms& terms, int first, int count,
                   const std::vector<Eigen::Vector4i>& tets,
                   const std::vector<std::array<int, 16>>& element_blocks, ch08::System& system) {
  for (int l = 0; l < count; ++l)
    ch12::scatter(terms, l, tets[first + l], element_blocks[first + l], system.A, system.b);
}
#endif

}  // namespace

LaneScatterPass::LaneScatterPass(const ch08::PartSetup& setup, const Params& params)
    : colouring_(setup, setup.element_group),
      batched_(setup.model, setup.scene),
      a_bytes_(double(sizeof(Eigen::Matrix3d)) * double(setup.system.A.blocks.size())),
      cache_bytes_(params.cache_bytes),
      ahead_(a_bytes_ > double(params.cache_bytes)) {}

void LaneScatterPass::pass(const ch08::StepInput& in, const State& state, ch08::System& system) {
  using ch12::kLanes;
  const auto& tets = in.model.tets;
  const auto& element_blocks = system.index.element;
  batched_.end_pass(colouring_.for_coloured_groups([&](int first, int last, long long& fallbacks) {
    ch12::BatchTerms terms;  // on this thread's stack: no allocation, no sharing
    for (int e = first; e < last; e += kLanes) {
      const int count = std::min(kLanes, last - e);
      // The next batch of this group: its lines arrive while this batch's lanes compute.
      if (ahead_)
        fetch_ahead(e + count, std::min(last, e + count + kLanes), tets, element_blocks, state,
                    system);
      batched_.terms(e, count, tets, state, fallbacks, terms);
      scatter_batch(terms, e, count, tets, element_blocks, system);
    }
  }));
}

void LaneScatterPass::describe(std::ostream& out) const {
  // Formatted apart: the stream's precision stays the caller's.
  const double mib = 1 << 20;
  std::ostringstream line;
  line << std::fixed << std::setprecision(1) << "    A " << a_bytes_ / mib
       << " MiB against a last cache of " << double(cache_bytes_) / mib
       << " MiB: " << (ahead_ ? "the next batch fetched ahead" : "no fetching ahead") << "\n";
  out << line.str();
}

}  // namespace fem::ch14
