#pragma once
// The temporaries of atomic outputs (".NAME.tmpPID.EXT" beside NAME.EXT): a registry of the
// live ones, for a signal handler to remove, and the removal of those left by dead processes.

#include <string>

namespace terrain::io {

// Adds or removes a live temporary (thread-safe; at most 64 are held at once).
void register_temporary(const std::string& path);
void unregister_temporary(const std::string& path);

// Unlinks every registered temporary; async-signal-safe (for a handler that must exit).
void remove_registered_temporaries() noexcept;

// Removes ".STEM.tmpPID*" files beside `output` ("dir/STEM.ext") whose process PID no longer
// runs (left by a killed run: the main temporary and any sidecars, or a whole temporary
// directory). `whole_name`: the prefix is ".NAME.tmp" with the extension kept (directories).
// Returns how many.
int remove_stale_temporaries(const std::string& output, bool whole_name = false) noexcept;

}  // namespace terrain::io
