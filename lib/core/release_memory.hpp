// Hands the heap's free pages back to the operating system.
//
// A stage allocates tens of bytes per point in temporaries from several threads. glibc keeps
// what they free in per-thread arenas, and after a large block is freed it raises its mmap
// threshold, so later blocks of up to that size stay in the heap too: the process's resident
// size then never falls back between stages, and whatever the host allocates next (the
// caller's copy of the oriented normals, say) lands on top of it. At a million points that
// was 60 MB of a 150 MB peak. Called at the end of every long call and on destroy.
#pragma once

namespace gmpu {

void release_free_memory() noexcept;

}  // namespace gmpu
