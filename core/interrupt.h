#pragma once
// A long run stops cleanly on SIGINT (Ctrl-C) or SIGTERM: while an InterruptWatch lives, either signal only
// sets a flag, which the run's loop reads between steps; the run then writes what it has, marked interrupted,
// and the command exits with 128 + the signal's number, as a shell reports a process the signal ended.
#include <csignal>
#include <stdexcept>
#include <string>

namespace needle {

class InterruptWatch {
 public:
  InterruptWatch();   // installs the handlers (and clears an earlier signal)
  ~InterruptWatch();  // restores the ones before
  InterruptWatch(const InterruptWatch&) = delete;
  InterruptWatch& operator=(const InterruptWatch&) = delete;
  int signal() const;  // the signal received, 0 while none

 private:
  struct sigaction old_int_ {}, old_term_ {};
};

// Thrown once what an interrupted run had is written; main turns it into exit code 128 + signal.
struct Interrupted : std::runtime_error {
  Interrupted(int signal_number, const std::string& what) : std::runtime_error(what), signal(signal_number) {}
  int signal;
};

std::string signal_name(int signal);  // "SIGINT", "SIGTERM" or "signal N"

}  // namespace needle
