#pragma once
// Progress of long work on stderr: done / total, elapsed time, ETA and what runs now. On a
// terminal one bar redrawn in place (at most 10 times a second); otherwise (logs, CI) one line
// at most every `log_every` seconds, plus the lines a caller logs (a finished sweep group).
// The one progress display of the sfx commands; stdout stays for results.

#include <chrono>
#include <cstdint>
#include <string>

#include "base/host_clock.h"

namespace sfx {

// "42s", "3m07s", "1h05m", "3d04h"; "?" for a negative or absurd value.
std::string duration_text(double seconds);

class Progress {
public:
    // `what` prefixes the lines ("simulate"), `unit` names what is counted ("passes").
    // log_every = 0: no periodic lines when stderr is not a terminal, only log().
    Progress(std::string what, uint64_t total, std::string unit, double log_every = 5.0);
    ~Progress();  // finish()
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void set_label(const std::string& label);  // what runs now
    void set_total(uint64_t total);
    void set_done(uint64_t done);
    void advance(uint64_t n = 1) { set_done(m_done + n); }
    // A line of its own (the bar, if drawn, is cleared first and redrawn after).
    void log(const std::string& line);
    // Clears the bar so that other output can follow; the next update redraws it.
    void clear();
    // Clears the bar for good (a terminal) or prints the final line (a log, if any was printed).
    void finish();

    double elapsed() const;
    std::string eta() const;
    // "[12/48 points, 1m15s elapsed, ETA 25s]"
    std::string status() const;
    bool terminal() const { return m_tty; }
    const std::string& what() const { return m_what; }

private:
    void update(bool force);
    void draw();

    std::string m_what, m_unit, m_label;
    uint64_t m_total, m_done = 0;
    double m_log_every;
    bool m_tty, m_drawn = false, m_finished = false, m_logged = false;
    HostClock::time_point m_start, m_last_output;
};

}  // namespace sfx
