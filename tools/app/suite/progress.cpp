#include "progress.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <ostream>

#include <fmt/format.h>
#include <fmt/ostream.h>

namespace mpmvv::app::suite_file {

std::string duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  if (seconds < 60) return fmt::format("{:.0f}s", seconds);
  if (seconds < 3600) return fmt::format("{}m{:02d}s", int(seconds) / 60, int(seconds) % 60);
  return fmt::format("{}h{:02d}m", int(seconds) / 3600, (int(seconds) % 3600) / 60);
}

Progress::Progress(std::ostream& err, bool quiet, std::string prefix, int jobs)
    : err_(err), quiet_(quiet), tty_(isatty(fileno(stderr))), prefix_(std::move(prefix)), jobs_(jobs) {}

void Progress::show(const std::vector<std::size_t>& queue, const std::vector<CaseState>& state, std::size_t finished,
                    double finished_wall, std::size_t running, bool force) {
  if (quiet_) return;
  const auto now = Clock::now();
  if (!force && now - last_ < std::chrono::milliseconds(tty_ ? 500 : 60000) && (tty_ || finished == last_finished_))
    return;
  last_ = now;
  last_finished_ = finished;
  std::size_t completed = 0, failed = 0, broken = 0;
  for (std::size_t i : queue) {
    if (state[i].status == "completed") ++completed;
    else if (state[i].status == "failed" || state[i].status == "lost") ++failed;
    else if (state[i].status != "pending" && state[i].status != "running") ++broken;
  }
  const std::size_t remaining = queue.size() - finished;
  const double eta = finished ? finished_wall / double(finished) * double(remaining) / double(jobs_) : NAN;
  const int width = 24;
  const int filled = queue.empty() ? width : int(width * finished / queue.size());
  const std::string bar = std::string(std::size_t(filled), '#') + std::string(std::size_t(width - filled), '.');
  const std::string line = fmt::format("{}[{}] {}/{} cases: {} completed, {} failed or lost, {} crashed/timeout/error, {} running, ETA {}",
                                       prefix_, bar, finished, queue.size(), completed, failed, broken, running,
                                       duration(eta));
  if (tty_) fmt::print(err_, "\r{:<110}", line);
  else fmt::print(err_, "{}\n", line);
  err_.flush();
}

}  // namespace mpmvv::app::suite_file
