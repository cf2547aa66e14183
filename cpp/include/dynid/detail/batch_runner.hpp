// Internal (dynid::detail, not API): the loop of every batch. `count` samples are split in chunks
// claimed from a shared counter by up to `threads` threads (the calling one included), each
// running on its own slot of the BatchWorkspace.
//
// - The interrupt: the calling thread runs the check between chunks, at most every 20 ms;
//   when it returns true every thread stops after its current chunk and batch::Interrupted is
//   thrown once all have joined.
// - Threads that cannot be started (the system's thread limit, no memory for a stack) are not
//   an error: the batch runs on those that did start, at least the calling one. Their
//   workspaces exist before any thread starts, so a started thread allocates nothing.
// - An exception in any thread stops the others; the first is rethrown after all joined.
#pragma once

#include <Eigen/Core>

#include "dynid/batch.hpp"

namespace dynid::detail {

// Samples below this many per thread run on fewer threads.
constexpr Eigen::Index kMinSamplesPerThread = 512;
// Samples claimed at a time by default: large enough that the shared counter and the clock are
// read rarely, small enough that a chunk takes a millisecond or less (about 1 us per sample for
// n = 7); a multiple of every lane count. chunk_for_work() scales it down for costlier samples.
constexpr Eigen::Index kChunk = 256;
static_assert(kChunk % 8 == 0, "chunks in whole vectors of every lane count");

// A chunk of about `budget` elementary operations when one sample costs `work_per_sample`.
Eigen::Index chunk_for_work(double work_per_sample, double budget = 65536.0);

// work(context, slot, begin, end) evaluates samples [begin, end) with the buffers of slot `slot`
// and returns the first of them whose result is not finite, or -1.
using ChunkWork = Eigen::Index (*)(void* context, int slot, Eigen::Index begin, Eigen::Index end);

// The threads a batch of `count` samples runs on: min(ws.threads(), count / kMinSamplesPerThread),
// at least one.
int batch_threads(const BatchWorkspace& ws, Eigen::Index count);

// Runs work over [0, count) in chunks of `chunk` samples on up to `threads` threads, slot k on
// thread k (0: the calling thread), with `interrupt` checked between chunks (may be empty).
batch::Report run_chunks(Eigen::Index count, int threads, Eigen::Index chunk, ChunkWork work,
                         void* context, const BatchInterrupt& interrupt);

template <class Work>  // Work: Eigen::Index(int slot, Eigen::Index begin, Eigen::Index end)
batch::Report run_chunks(Eigen::Index count, int threads, Eigen::Index chunk, Work& work,
                         const BatchInterrupt& interrupt) {
  return run_chunks(
      count, threads, chunk,
      [](void* context, int slot, Eigen::Index begin, Eigen::Index end) {
        return (*static_cast<Work*>(context))(slot, begin, end);
      },
      &work, interrupt);
}

}  // namespace dynid::detail
