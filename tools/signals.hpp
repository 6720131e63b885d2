#pragma once
// SIGINT and SIGTERM: the first sets a flag that the progress callbacks turn into a
// cancellation (the work stops, temporaries are removed while unwinding, exit 128+signal);
// a second one removes the registered temporaries and exits at once.

namespace terrain::cli {

void install_signal_handlers();

// The signal received (SIGINT, SIGTERM) or 0.
int pending_signal();

// Throws the cancellation when a signal is pending (cheap; for loops without progress).
void check_interrupted();

}  // namespace terrain::cli
