#include "remove_on_interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <mutex>

namespace clothwind::tools {
namespace {

constexpr int kSlots = 8;
constexpr size_t kPathMax = 4096;
// The handler reads these without a lock (only async-signal-safe calls there): a slot's path is
// written before its flag is set, and its flag cleared before the slot is reused.
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];
std::mutex g_register;  // between registrations (threads), never taken by the handler
bool g_installed = false;

void OnInterrupt(int sig) {
  for (int i = 0; i < kSlots; ++i)
    if (g_used[i].load()) ::unlink(g_paths[i]);
  // Die of the signal, as without the handler.
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

RemoveOnInterrupt::RemoveOnInterrupt(const std::string& path) {
  std::lock_guard<std::mutex> lock(g_register);
  if (!g_installed) {
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_handler = OnInterrupt;
    sigemptyset(&action.sa_mask);
    // A signal the process ignores stays ignored: `nohup` (SIGHUP) and a shell's background jobs
    // (SIGINT) must not start dying of it.
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old;
      if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
      ::sigaction(sig, &action, nullptr);
    }
    g_installed = true;
  }
  if (path.size() >= kPathMax) {
    std::fprintf(stderr, "warning: %s is not removed if interrupted (path too long)\n", path.c_str());
    return;
  }
  for (int i = 0; i < kSlots; ++i) {
    if (g_used[i].load()) continue;
    std::memcpy(g_paths[i], path.c_str(), path.size() + 1);
    g_used[i].store(true);
    slot_ = i;
    return;
  }
  std::fprintf(stderr, "warning: %s is not removed if interrupted (more than %d temporaries)\n", path.c_str(), kSlots);
}

RemoveOnInterrupt::~RemoveOnInterrupt() {
  if (slot_ < 0) return;
  std::lock_guard<std::mutex> lock(g_register);
  g_used[slot_].store(false);
}

}  // namespace clothwind::tools
