// A suite's progress on its standard error: a bar, the count of each outcome
// and an estimate of the time left. On a terminal one line rewritten twice a
// second; in a log a line once a minute (and one when a case ends, printed
// where it is reaped).
#pragma once

#include <chrono>
#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

#include "manifest.hpp"

namespace mpmvv::app::suite_file {

// "42s", "3m05s", "2h10m"; "?" for no estimate.
std::string duration(double seconds);

class Progress {
 public:
  Progress(std::ostream& err, bool quiet, std::string prefix, int jobs);

  bool terminal() const { return tty_; }

  // The line for the cases `queue` of `state`, `finished` of them in
  // `finished_wall` seconds of case time; at most as often as said above
  // unless `force`.
  void show(const std::vector<std::size_t>& queue, const std::vector<CaseState>& state, std::size_t finished,
            double finished_wall, std::size_t running, bool force);

 private:
  using Clock = std::chrono::steady_clock;
  std::ostream& err_;
  bool quiet_, tty_;
  std::string prefix_;
  int jobs_;
  Clock::time_point last_ = Clock::now() - std::chrono::seconds(60);
  std::size_t last_finished_ = 0;
};

}  // namespace mpmvv::app::suite_file
