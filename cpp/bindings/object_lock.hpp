// One Python thread at a time per stateful C++ object (MomentumObserver, RecursiveLeastSquares).
// Their long calls (run, update_batch) release the GIL, so without a lock two Python threads
// that share one object would interleave its updates and silently lose samples (issue 22).
// lock_object(&obj) holds obj's lock until the returned guard dies: calls on one object run one
// after the other, calls on different objects in parallel. It is taken with the GIL held and,
// when it is busy, waits with the GIL released, so that the holder, which needs the GIL again
// at the end of its call, can always finish: no deadlock.
#pragma once

#include <mutex>

namespace dynid::binding {

std::unique_lock<std::mutex> lock_object(const void* object);

}  // namespace dynid::binding
