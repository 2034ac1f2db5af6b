// The one link between the steppers and the allocation counter: the counter, when it is
// linked into a program, sets this hook; PhaseTimer reads it to count per phase.
#pragma once

namespace fem {

// The number of heap allocations so far, or null (the default) when no counter is linked.
extern long long (*allocation_count_hook)();

}  // namespace fem
