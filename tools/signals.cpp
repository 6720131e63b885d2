#include "signals.hpp"

#include <signal.h>
#include <unistd.h>

#include <atomic>

#include "terrain/core/error.hpp"
#include "terrain/io/temporary_files.hpp"

namespace terrain::cli {
namespace {

std::atomic<int> received{0};

extern "C" void on_signal(int signal) {
    if (received.exchange(signal) != 0) {
        io::remove_registered_temporaries();
        ::_exit(128 + signal);
    }
}

}  // namespace

void install_signal_handlers() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

int pending_signal() {
    return received.load();
}

void check_interrupted() {
    if (received.load() != 0) throw Error("progress", "interrupted");
}

}  // namespace terrain::cli
