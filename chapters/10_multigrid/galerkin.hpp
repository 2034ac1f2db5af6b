// Chapter 10: the Galerkin product A_c = P^T A P, the next level's matrix. Its pattern and
// every product's place in it are found once, at set-up (the symbolic tables, as a sparse
// direct solver's analyzePattern does); a refresh then only multiplies blocks and adds them
// where the tables say, on the team, in a fixed order.
#pragma once

#include <algorithm>
#include <vector>

#include "chapters/10_multigrid/aggregation.hpp"
#include "chapters/10_multigrid/level.hpp"

namespace fem::ch10 {

// A P on the pattern of A times P's, stored whole (each row written by its owner), and the
// place of every product A_k P_m, row by row in loop order.
template <int B>
void build_ap_pattern(Level<B>& fine) {
  const auto& A = fine.A;
  const auto& P = fine.transfer.P;
  GalerkinTables<B>& g = fine.galerkin;
  const int n = fine.nodes();
  Rows rows(n);
  for (int i = 0; i < n; ++i) {
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        rows[i].push_back(P.column[m]);
    sort_unique(rows[i]);
  }
  g.AP = BlockCsr<B, kModes>(rows);
  g.AP.blocks.clear();  // the values are stored transposed, in ap_transposed
  g.ap_transposed.resize(g.AP.column.size());
  g.ap_target.clear();
  g.ap_row_first.resize(n + 1);
  for (int i = 0; i < n; ++i) {
    g.ap_row_first[i] = static_cast<int>(g.ap_target.size());
    for (int k = A.row_start[i]; k < A.row_start[i + 1]; ++k)
      for (int m = P.row_start[A.column[k]]; m < P.row_start[A.column[k] + 1]; ++m)
        g.ap_target.push_back(g.AP.find(i, P.column[m]));
  }
  g.ap_row_first[n] = static_cast<int>(g.ap_target.size());
}

// The next level's pattern, P^T (A P), and the Galerkin tables by coarse row: for each entry
// of R's row c (block m of P in fine row i), the blocks of A P's row i from column c on,
// and where each product P_m^T (A P)_q lands in row c.
template <int B>
void build_galerkin_tables(Level<B>& fine, int count, Level<kModes>& coarse) {
  const auto& P = fine.transfer.P;
  const auto& R = fine.transfer.R;
  GalerkinTables<B>& g = fine.galerkin;
  const auto& AP = g.AP;
  Rows coarse_rows(count);
  for (int i = 0; i < fine.nodes(); ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m)
      for (int q = AP.row_start[i]; q < AP.row_start[i + 1]; ++q)
        coarse_rows[P.column[m]].push_back(AP.column[q]);
  for (auto& row : coarse_rows) sort_unique(row);
  coarse.A = BlockCsr<kModes, kModes>(coarse_rows);
  coarse.values = coarse.A.blocks.data();
  g.upper_first.resize(P.column.size());
  for (int i = 0; i < fine.nodes(); ++i)
    for (int m = P.row_start[i]; m < P.row_start[i + 1]; ++m) {
      const auto first = AP.column.begin() + AP.row_start[i],
                 last = AP.column.begin() + AP.row_start[i + 1];
      g.upper_first[m] =
          static_cast<int>(std::lower_bound(first, last, P.column[m]) - AP.column.begin());
    }
  g.coarse_target.clear();
  g.coarse_row_first.resize(count + 1);
  for (int c = 0; c < count; ++c) {
    g.coarse_row_first[c] = static_cast<int>(g.coarse_target.size());
    for (int e = R.row_start[c]; e < R.row_start[c + 1]; ++e) {
      const int i = R.column[e], m = fine.transfer.restriction_source[e];
      for (int q = g.upper_first[m]; q < AP.row_start[i + 1]; ++q)
        g.coarse_target.push_back(coarse.A.find(c, AP.column[q]));
    }
  }
  g.coarse_row_first[count] = static_cast<int>(g.coarse_target.size());
}

// A_c = P^T (A P) on the fixed patterns, by the team: A P by fine rows, each row by the
// thread that owns it; then the blocks on and right of the diagonal of A_c by the owner of
// each coarse row, summed over R's row in increasing fine row, the same order for any
// thread count; then the rest by symmetry (after the barrier: another row's blocks). A P is
// stored transposed, (A P)^T = P^T A (A symmetric), so that both products work on 6-row
// columns: (A P)_q^T += P_m^T A_k^T, then A_c += R_e ((A P)_q^T)^T.
template <int B>
void galerkin_product(Level<B>& level, Level<kModes>& coarse, bool collective) {
  const auto& A = level.A;
  const auto& P = level.transfer.P;
  const auto& R = level.transfer.R;
  GalerkinTables<B>& g = level.galerkin;
  const auto& AP = g.AP;
  ch09::for_parts(level.rows.part, collective, [&](int first, int last) {
    for (int q = AP.row_start[first]; q < AP.row_start[last]; ++q) g.ap_transposed[q].setZero();
    const int* target = g.ap_target.data() + g.ap_row_first[first];
    for (int k = A.row_start[first]; k < A.row_start[last]; ++k) {
      const int j = A.column[k];
      for (int m = P.row_start[j]; m < P.row_start[j + 1]; ++m)
        add_product_transposed(g.ap_transposed[*target++], g.p_transposed[m], level.values[k]);
    }
  });
  auto& Ac = coarse.A;
  ch09::for_parts(coarse.rows.part, collective, [&](int first, int last) {
    const int* target = g.coarse_target.data() + g.coarse_row_first[first];
    for (int c = first; c < last; ++c) {
      for (int k = coarse.diagonal[c]; k < Ac.row_start[c + 1]; ++k) Ac.blocks[k].setZero();
      for (int e = R.row_start[c]; e < R.row_start[c + 1]; ++e) {
        const int i = R.column[e];
        for (int q = g.upper_first[level.transfer.restriction_source[e]]; q < AP.row_start[i + 1];
             ++q)
          add_product_transposed(Ac.blocks[*target++], R.blocks[e], g.ap_transposed[q]);
      }
      // Modes an aggregate lacks: a zero row and column, given the identity (I - S).
      Ac.blocks[coarse.diagonal[c]].diagonal() += coarse.missing_modes[c];
    }
  });
  ch09::for_parts(coarse.rows.part, collective, [&](int first, int last) {
    for (int c = first; c < last; ++c)
      for (int k = Ac.row_start[c]; k < coarse.diagonal[c]; ++k)
        Ac.blocks[k] = Ac.blocks[coarse.transpose[k]].transpose();
  });
}

}  // namespace fem::ch10
