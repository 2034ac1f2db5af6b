"""The exercises that tests/scripts/test_exercises.py does as a student does them, and the
variant that stands for each chapter in the checks of every variant."""

# The exercises: chapter, variant name, the text replaced in the variant's files (the scripted
# change: (old, new) in stepper.cpp, or (file, old, new)), and the README commands to run (NAME
# stands for the variant's name).
EXERCISES = [
    {"id": "01/2", "chapter": "01", "name": "ex_setzero",
     "change": [("dfdx_.coeffs().setZero();", "dfdx_.setZero();")],
     "bench": "build/release/fem_bench --chapters 01,01_NAME --mesh meshes/test_beam.msh --steps 5 --warmup 1 --no-solvers --no-json",
     "expect": "more allocations",
     "test": "./tutorial.sh test -L ch01_NAME", "test_passes": True},
    {"id": "02/1", "chapter": "02", "name": "ex_alias",
     "change": [("b_.noalias() = h * (dfdx_ * scaled_v_);", "b_ = h * (dfdx_ * scaled_v_);")],
     "bench": "build/release/fem_bench --chapters 02,02_NAME --mesh meshes/test_beam.msh --steps 5 --no-solvers --no-json",
     "expect": "more allocations"},
    {"id": "05/1", "chapter": "05", "name": "ex_nodiag",
     "change": [("block(A_, c.node, diagonal_block_[c.node]) += Eigen::Matrix3d::Identity() - c.filter;",
                 "(void)diagonal_block_;")],
     "test": "./tutorial.sh test -L ch05_NAME", "test_passes": False,
     "failing": "constrained velocities are the prescribed ones"},
    {"id": "06/1", "chapter": "06", "name": "ex_colmajor",
     "change": [("q.noalias() = A.transpose() * y;", "q.noalias() = A * y;"),
                ("q.noalias() = A.transpose() * p;", "q.noalias() = A * p;")],
     "bench": "build/release/fem_bench --chapters 06,06_NAME --steps 30 --no-solvers --no-json",
     "expect": "same iterations"},
    {"id": "06/2", "chapter": "06", "name": "ex_cold",
     "change": [("  // Warm start: y_ still holds the previous step's answer; pcg_solve filters it.\n",
                 "  y_.setZero();  // the warm start off\n")],
     "bench": "build/release/fem_bench --chapters 06,06_NAME --steps 30 --no-solvers --no-json",
     "expect": "more iterations"},
    {"id": "06/3", "chapter": "06", "name": "ex_nofilter",
     "change": [("      r -= step * q;\n      filter(constraints, r);\n", "      r -= step * q;\n"),
                ("      s = inverse_diagonal.cwiseProduct(r);\n      filter(constraints, s);\n",
                 "      s = inverse_diagonal.cwiseProduct(r);\n")],
     "test": "./tutorial.sh test -L ch06_NAME", "test_passes": False,
     "failing": "constrained velocities are the prescribed ones"},
    {"id": "07/2", "chapter": "07", "name": "ex_scalar_jacobi",
     "change": [("block_pcg.cpp", "inverse_diagonal[i] = A.blocks[diagonal_block[i]].inverse();",
                 "inverse_diagonal[i] = A.blocks[diagonal_block[i]].diagonal().cwiseInverse().asDiagonal();")],
     "bench": "build/release/fem_bench --chapters 07,07_NAME --steps 30 --no-solvers --no-json",
     "expect": "more iterations"},
    {"id": "07/3", "chapter": "07", "name": "ex_threads",
     "change": [("block_sparse.hpp", "    multiply_rows(x, y, 0, block_rows());\n",
                 "#pragma omp parallel for schedule(static)\n"
                 "    for (int i = 0; i < block_rows(); ++i) multiply_rows(x, y, i, i + 1);\n"),
                ("stepper.hpp", "  const StepProfile& profile() const override { return profile_; }\n",
                 "  const StepProfile& profile() const override { return profile_; }\n"
                 "  bool uses_threads() const override { return true; }\n")],
     "bench": "build/release/fem_bench --chapters 07,07_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "threaded rows"},
    {"id": "08/1", "chapter": "08", "name": "ex_last_rotation",
     "change": [("element_kernels.cpp",
                 "Eigen::Quaterniond q = predicted_rotation(rotations_[e], previous_rotations_[e]);",
                 "Eigen::Quaterniond q = rotations_[e];")],
     "bench": "build/release/fem_bench --chapters 08,08_NAME --steps 30 --no-solvers --no-json",
     "expect": "same iterations"},
    {"id": "09/2", "chapter": "09", "name": "ex_reduction",
     "change": [("parallel_pcg.cpp",
                 "  for (const int c : StaticShare(chunks_.count()))\n"
                 "    partial_pq_[c] = pcg_product(A, p_, q_, chunks_.start[c], chunks_.start[c + 1]);\n"
                 "  return sum_in_order(partial_pq_);\n",
                 "  static double pq;  // shared by the team, as an orphaned reduction needs\n"
                 "#pragma omp single\n"
                 "  pq = 0.0;\n"
                 "#pragma omp for schedule(static) reduction(+ : pq)\n"
                 "  for (int c = 0; c < chunks_.count(); ++c)\n"
                 "    pq += pcg_product(A, p_, q_, chunks_.start[c], chunks_.start[c + 1]);\n"
                 "  return pq;\n")],
     "test": "./tutorial.sh test -L ch09_NAME", "test_passes": False,
     "failing": "the same state to the last bit on 1, 2 and 3 threads"},
    {"id": "10/4", "chapter": "10", "name": "ex_yardstick",
     "change": [("refresh_rule.cpp",
                 "    measure_next_ = false;\n  }\n",
                 "    measure_next_ = false;\n  } else if (!measure_next_) {\n"
                 "    cycles_after_refresh_ = std::min(cycles_after_refresh_, last);\n  }\n")],
     "bench": "build/release/fem_bench --chapters 10,10_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons multigrid --chapter 10_NAME"},
    # Written in chapter 10's README, done in a variant of chapter 09 and measured beside both.
    {"id": "10/5", "chapter": "09", "readme": "10", "name": "ex_guess",
     "change": [("stepper.hpp", "  using Guess = ch08::WarmStart;\n", "  using Guess = ch10::Extrapolation;\n"),
                ("stepper.hpp", "#include \"chapters/09_threads/parts.hpp\"\n",
                 "#include \"chapters/09_threads/parts.hpp\"\n"
                 "#include \"chapters/10_multigrid/parts.hpp\"\n")],
     "bench": "build/release/fem_bench --chapters 09,09_NAME,10 --steps 30 --no-solvers --no-json",
     "expect": "measured", "also": ["10_multigrid"]},
    {"id": "11/2", "chapter": "11", "name": "ex_slabs",
     "change": [("renumbered_nodes.hpp", "static constexpr int kSlabs = 64;",
                 "static constexpr int kSlabs = 8;")],
     "bench": "build/release/fem_bench --chapters 11,11_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons node-order --chapter 11_NAME"},
    {"id": "12/1", "chapter": "12", "name": "ex_widened",
     "change": [("stepper.hpp", "using Preconditioner = ch12::ReducedMultigrid<float>;",
                 "using Preconditioner = ch12::ReducedMultigrid<double>;")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "measured"},
    {"id": "12/2", "chapter": "12", "name": "ex_unpadded",
     "change": [("reduced_kernels.hpp",
                 "  using Column = Eigen::Matrix<float, kPaddedColumn<R>, 1>;\n  for (int j = 0; j < C; ++j)\n"
                 "    sums.of(j) += Eigen::Map<const Column>(M.data() + R * j).template cast<Real>() * x[j];\n",
                 "  for (int j = 0; j < C; ++j)\n"
                 "    sums.of(j).template head<R>() += M.col(j).template cast<Real>() * x[j];\n")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons half-the-bytes --chapter 12_NAME --steps 10"},
    {"id": "12/4", "chapter": "12", "name": "ex_lanes",
     "change": [("batch_rotations.hpp", "constexpr int kLanes = 8;", "constexpr int kLanes = 4;")],
     "bench": "build/release/fem_bench --chapters 12,12_NAME --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons batched-elements --chapter 12_NAME"},
    {"id": "14/1", "chapter": "14", "name": "ex_rowpairs",
     "change": [("lane_v_cycle.hpp", "using PaddedLanes = LaneFineLevel;", "using PaddedLanes = RowPairFineLevel;"),
                ("lane_v_cycle.hpp", "#include \"chapters/14_every_lane/fine_smoothing.hpp\"\n",
                 "#include \"chapters/14_every_lane/fine_smoothing.hpp\"\n"
                 "#include \"chapters/14_every_lane/row_pairs.hpp\"\n"),
                ("course_files", "row_pairs.cpp\n", "")],
     "bench": "build/release/fem_bench --chapters 14,14_NAME --threads 1,2 --steps 30 --no-solvers --no-json",
     "expect": "measured",
     "lesson": "build/release/fem_lessons every-lane --chapter 14_NAME --steps 3"},
]


# The exercise whose variant stands for its chapter in the checks of every variant (its change
# keeps the generic tests passing); a chapter of the range with none here, or whose exercise is
# not run, gets an unchanged variant NN_mine. And the lesson each variant's copy runs.
STANDS_FOR = {"01": "01/2", "02": "02/1", "06": "06/2", "07": "07/2", "08": "08/1", "09": "10/5",
              "10": "10/4", "11": "11/2", "12": "12/4",
              "14": "14/1"}
LESSONS = {"07": "spmv", "08": "rotations", "09": "threads-element", "10": "multigrid",
           "14": "every-lane"}
