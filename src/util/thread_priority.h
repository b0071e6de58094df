#pragma once
// Background work (mapping, loop closing) shares the CPU with tracking; on one core the scheduler
// would split it evenly and every frame would take twice its own time. A higher nice value for the
// background thread lets tracking run first while the background still gets the idle time.

namespace edgeslam {

// Raises the calling thread's nice value by `increment` (0 does nothing). Returns false, and
// leaves the thread as it was, when the system refuses.
bool lowerCurrentThreadPriority(int increment);

// The calling thread's nice value.
int currentThreadNice();

}  // namespace edgeslam
