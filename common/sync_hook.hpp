// The one link between the steppers and chapter 09's count of synchronizations: chapter 09's
// parallel.hpp, which holds the count, sets this hook; PhaseTimer reads it to count per phase.
// The chapters before 09 open no parallel region, link no count, and report zero.
#pragma once

namespace fem {

// Parallel regions opened and barriers met, by all steppers so far (chapter 09's SyncCounts).
struct Synchronizations {
  long long regions = 0, barriers = 0;
};

// The count so far, or null (the default) when no chapter that counts is linked.
extern Synchronizations (*sync_count_hook)();

}  // namespace fem
