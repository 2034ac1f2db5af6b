// The pair lanes' kernels (chapters/14_every_lane) alone, against the kernels they replace,
// with their data in cache: the fine level's float smoothing step and residual, and the
// double product q = A p, each timed as the roofline times a kernel alone (best of repeated
// timings of many calls in one parallel region), old and new alternated for several rounds
// in one run, and set beside the bound of each one's own bytes and flops under the machine's
// roofs measured in the same run.
//
// Chapter 14's probe, kept with the roofline's programs because it times with their code
// (kernels_alone.hpp, roofs.hpp): no file under chapters/ includes one under apps/.
//
//   lanes_bench [--mesh meshes/plate_poster.msh] [--rounds 5] [--roof-seconds 0.3] [--threads N]
#include <Eigen/Core>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/roofline/kernels_alone.hpp"
#include "apps/roofline/roofs.hpp"
#include "chapters/01_naive/work.hpp"
#include "chapters/07_block_sparse/work.hpp"
#include "chapters/09_threads/parallel.hpp"
#include "chapters/09_threads/parallel_pcg.hpp"
#include "chapters/10_multigrid/work.hpp"
#include "chapters/12_half_the_bytes/reduced_kernels.hpp"
#include "chapters/12_half_the_bytes/stepper.hpp"
#include "chapters/14_every_lane/fine_smoothing.hpp"
#include "chapters/14_every_lane/lane_product.hpp"
#include "chapters/14_every_lane/row_pairs.hpp"
#include "common/cli.hpp"
#include "common/mesh.hpp"
#include "common/threads.hpp"

using namespace fem;

namespace {

struct Options {
  std::string mesh;
  int rounds = 0;
  double roof_seconds = 0.0;
  int threads = 0;  // 0: 1 and 2 threads
};

// The options, or nothing after --help; throws UsageError for an unknown option or a bad value.
std::optional<Options> parse(int argc, char** argv) {
  ArgParser args("lanes_bench",
                 "Chapter 14's pair lanes' kernels alone against the kernels they replace, old "
                 "and new alternated, each beside the bound of its own bytes and flops under the "
                 "machine's roofs.");
  args.option("mesh", "FILE", "the mesh whose system and finest level the kernels run on",
              "meshes/plate_poster.msh");
  args.option("rounds", "N", "rounds of old and new timings, alternated (the best is kept)", "5");
  args.option("roof-seconds", "S", "seconds per roof measurement; 0: no roofs, times only", "0.3");
  args.option("threads", "N", "time at N threads only; 0: at 1 and 2", "0");
  if (!args.parse(argc, argv)) return std::nullopt;
  Options o;
  o.mesh = resolve_mesh_path(args.get("mesh"));
  o.rounds = args.get_int("rounds");
  o.roof_seconds = args.get_double("roof-seconds");
  o.threads = args.get_int("threads");
  if (o.rounds < 1) throw UsageError("--rounds must be at least 1");
  if (!(o.roof_seconds >= 0.0)) throw UsageError("--roof-seconds must be 0 or more");
  if (o.threads < 0 || o.threads > 2) throw UsageError("--threads must be 0, 1 or 2");
  if (!std::filesystem::is_regular_file(o.mesh)) throw UsageError("no mesh file " + o.mesh);
  return o;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five;
  in >> one >> five;
  return one + " (1 min), " + five + " (5 min)";
}

// A kernel pair: the old one and the new one, each with its own count of one call.
struct Contest {
  std::string name;
  PhaseWork old_work, new_work;
  std::function<void()> old_run, new_run;
};

// The fine level's smoothing step (a step after the first, as the roofline times it) and
// residual: the padded columns' (the V-cycle's own kernels) against the lanes' (`name`).
template <class Lanes>
std::vector<Contest> fine_contests(ch12::HalfBytesStepper& stepper, Lanes& lanes,
                                   const std::string& name) {
  auto& fine = lanes.level;
  const int step = std::min(1, ch10::smoothing_steps(fine) - 1);
  const std::vector<ch10::LevelSize> levels =
      ch10::multigrid_levels(stepper.preconditioner().multigrid());
  PhaseWork old_step = ch10::v_cycle_work({levels.front()}, 1, sizeof(float), true).parts.front();
  const auto& part = source_level(fine).rows.part;
  Contest smoothing{"fine smoothing step (float), " + name, old_step, lanes.smoothing_work(),
                    [&fine, &part, step] {
                      ch09::for_parts(part, true, [&](int first, int last) {
                        ch10::smooth(fine, step, first, last, fine.vectors.b, &fine.vectors.x,
                                     fine.vectors.y, true);
                      });
                    },
                    [&fine, &lanes, &part, step] {
                      ch09::for_parts(part, true, [&](int first, int last) {
                        ch14::smooth_rows(lanes, step, first, last, fine.vectors.b, &fine.vectors.x,
                                          fine.vectors.y);
                      });
                    }};
  Contest residual{"fine residual (float), " + name, PhaseWork{}, lanes.residual_work(),
                   [&fine, &part] {
                     ch09::for_parts(part, true, [&](int first, int last) {
                       ch10::residual(fine, first, last, fine.vectors.b, fine.vectors.x);
                     });
                   },
                   [&fine, &lanes, &part] {
                     ch09::for_parts(part, true, [&](int first, int last) {
                       ch14::residual_rows(lanes, first, last, fine.vectors.b, fine.vectors.x);
                     });
                   }};
  // Counted alike but for the matrix: 3x3 floats and an index a block, a start a row.
  const double blocks = double(lanes.blocks.blocks()), rows = lanes.blocks.rows();
  const double old_matrix = 36.0 * blocks + 4.0 * (blocks + rows + 1);
  residual.old_work = residual.new_work;
  residual.old_work.bytes_read += old_matrix - lanes.blocks.bytes();
  residual.old_work.working_set += old_matrix - lanes.blocks.bytes();
  return {smoothing, residual};
}

// The PCG's product on its fixed row chunks: the 3x3 block rows against the pair lanes.
struct ProductData {
  ch09::RowChunks chunks;
  Eigen::VectorXd p, q;
};

template <class Lanes>
Contest product_contest(const ch07::BlockSparseMatrix& A, const Lanes& lanes,
                        std::shared_ptr<ProductData> d, const std::string& name) {
  d->chunks = ch09::RowChunks(A);
  d->p = Eigen::VectorXd::LinSpaced(3 * A.block_rows(), 1e-3, 1.0);
  d->q = d->p;
  const double vector = 8.0 * double(d->p.size()), matrix = ch07::matrix_bytes(A);
  Contest c;
  c.name = "product q = A p (double), " + name;
  c.old_work = ch01::phase_work("product", matrix + vector, vector, vector,
                                18.0 * double(A.blocks.size()), matrix + 2 * vector);
  c.new_work = lanes.work();
  c.old_run = [d, &A] {
    for (const int k : ch09::StaticShare(d->chunks.count()))
      A.multiply_rows(d->p, d->q, d->chunks.start[k], d->chunks.start[k + 1]);
  };
  c.new_run = [d, &lanes] {
    for (const int k : ch09::StaticShare(d->chunks.count()))
      lanes.multiply_rows(d->p, d->q, d->chunks.start[k], d->chunks.start[k + 1]);
  };
  return c;
}

void report(const Contest& c, int threads, const roofline::Roofs& roofs, double old_s,
            double new_s) {
  const bool roofed = !roofs.levels.empty();
  const double old_bound = roofed ? roofline::bound_seconds(roofs, c.old_work) : 0.0;
  const double new_bound = roofed ? roofline::bound_seconds(roofs, c.new_work) : 0.0;
  const char* level =
      roofed ? roofline::fitting_level(roofs, c.new_work.working_set).level.name.c_str() : "-";
  std::printf(
      "| %s | %d | %.2f | %.2f | %.3f | %.0f / %.0f | %s | %.2f / %.2f | %.0f%% | %.0f%% | "
      "%.0f%% |\n",
      c.name.c_str(), threads, 1e6 * old_s, 1e6 * new_s, new_s / old_s, 1e-3 * c.old_work.bytes(),
      1e-3 * c.new_work.bytes(), level, 1e6 * old_bound, 1e6 * new_bound, 100 * old_bound / old_s,
      100 * new_bound / new_s, 100 * old_bound / new_s);
}

// The set-up each step adds: the values copied into the lanes (by rows, every thread).
void time_fills(ch14::LaneFineLevel& fine, ch14::LaneProduct& product,
                const ch07::BlockSparseMatrix& A) {
  const double fine_fill = roofline::best_call_seconds(1, [&fine] {
    for (const int c : ch09::StaticShare(fine.blocks.rows())) fine.fill(c, c + 1);
  });
  const double product_fill = roofline::best_call_seconds(1, [&product, &A] {
    for (const int c : ch09::StaticShare(A.block_rows())) product.fill(A, c, c + 1);
  });
  std::printf("fill at 1 thread: fine level %.2f us, product %.2f us\n", 1e6 * fine_fill,
              1e6 * product_fill);
}

// Times the kernels of a cantilever on the mesh after three steps of chapter 12's stepper (the
// system and hierarchy the lanes are built from).
int bench(const Options& o) {
  std::printf("load before: %s\n", load_average().c_str());
  const Scene scene = make_scene("cantilever", load_mesh(o.mesh));
  ch12::HalfBytesStepper stepper(scene, SolverSettings{});
  State state = rest_state(scene);
  for (int k = 0; k < 3; ++k) stepper.step(state);
  ch12::ReducedVCycle<float>* cycle = &stepper.preconditioner().v_cycle();
  if (!cycle || stepper.preconditioner().multigrid().levels() < 2)
    throw std::runtime_error(o.mesh + " gives a multigrid of one level: no finest level to time");
  ch14::LaneFineLevel fine(cycle->fine_level());
  fine.fill(0, fine.blocks.rows());
  ch14::RowPairFineLevel row_pairs(cycle->fine_level());
  row_pairs.fill(0, row_pairs.blocks.rows());
  const ch07::BlockSparseMatrix& A = stepper.system_matrix();
  ch14::LaneProduct product(A);
  product.fill(A, 0, A.block_rows());
  ch14::PaddedLaneProduct padded(A);
  padded.fill(A, 0, A.block_rows());
  std::vector<Contest> contests = fine_contests(stepper, fine, "pair lanes");
  for (Contest& c : fine_contests(stepper, row_pairs, "row pairs")) contests.push_back(c);
  contests.push_back(
      product_contest(A, product, std::make_shared<ProductData>(), "pair lanes, packed"));
  contests.push_back(
      product_contest(A, padded, std::make_shared<ProductData>(), "pair lanes, padded"));
  std::printf("%s: %d nodes, %lld blocks\n", o.mesh.c_str(), A.block_rows(),
              static_cast<long long>(A.blocks.size()));
  const int max_threads = openmp_enabled() ? 2 : 1;
  std::printf(
      "| kernel | threads | old us | new us | new/old | kB old / new | level (new) | bound old / "
      "new us | old of its bound | new of its bound | new of old's bound |\n"
      "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|\n");
  for (int threads = 1; threads <= max_threads; ++threads) {
    if (o.threads > 0 && threads != o.threads) continue;
    // --roof-seconds 0: no roofs (the kernels' times and ratios only, quickly).
    const roofline::Roofs roofs =
        o.roof_seconds > 0
            ? roofline::measure_roofs(roofline::cache_levels(), threads, o.roof_seconds, false)
            : roofline::Roofs{};
    for (const roofline::LevelRoof& l : roofs.levels)
      std::printf("%d thread(s): %s read roof %.1f GB/s\n", threads, l.level.name.c_str(),
                  1e-9 * l.read);
    for (const Contest& c : contests) {
      double old_s = 1e30, new_s = 1e30;
      for (int round = 0; round < o.rounds; ++round) {
        old_s = std::min(old_s, roofline::best_call_seconds(threads, c.old_run));
        new_s = std::min(new_s, roofline::best_call_seconds(threads, c.new_run));
      }
      report(c, threads, roofs, old_s, new_s);
    }
  }
  time_fills(fine, product, A);
  std::printf("load after: %s\n", load_average().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return run_program("lanes_bench", [&] {
    const std::optional<Options> o = parse(argc, argv);
    return o ? bench(*o) : 0;
  });
}
