#include "app/progress.h"

#include <unistd.h>

#include <cmath>
#include <iostream>

namespace sfx {

std::string duration_text(double seconds) {
    if (!(seconds >= 0) || seconds > 1e10) return "?";
    const long s = long(std::lround(seconds));
    if (s >= 172800) return std::to_string(s / 86400) + "d" + (s % 86400 / 3600 < 10 ? "0" : "") +
                            std::to_string(s % 86400 / 3600) + "h";
    if (s < 60) return std::to_string(s) + "s";
    if (s < 3600)
        return std::to_string(s / 60) + "m" + (s % 60 < 10 ? "0" : "") + std::to_string(s % 60) +
               "s";
    return std::to_string(s / 3600) + "h" + (s % 3600 / 60 < 10 ? "0" : "") +
           std::to_string(s % 3600 / 60) + "m";
}

Progress::Progress(std::string what, uint64_t total, std::string unit, double log_every)
    : m_what(std::move(what)),
      m_unit(std::move(unit)),
      m_total(total),
      m_log_every(log_every),
      m_tty(isatty(2)),
      m_start(HostClock::now()),
      m_last_output(m_start) {}

Progress::~Progress() {
    finish();
}

void Progress::set_label(const std::string& label) {
    m_label = label;
    update(true);
}

void Progress::set_total(uint64_t total) {
    m_total = total;
    update(false);
}

void Progress::set_done(uint64_t done) {
    m_done = done;
    update(false);
}

double Progress::elapsed() const {
    return seconds_since(m_start);
}

std::string Progress::eta() const {
    if (m_done == 0 || m_done > m_total) return "?";
    return duration_text(elapsed() / double(m_done) * double(m_total - m_done));
}

std::string Progress::status() const {
    return "[" + std::to_string(m_done) + "/" + std::to_string(m_total) + " " + m_unit + ", " +
           duration_text(elapsed()) + " elapsed, ETA " + eta() + "]";
}

void Progress::update(bool force) {
    if (m_finished) return;
    const auto now = HostClock::now();
    const double since = seconds_between(m_last_output, now);
    if (m_tty) {
        // Redrawing costs a write: at most ten a second, and always for a new label.
        if (force || since >= 0.1) draw();
    } else if (m_log_every > 0 && since >= m_log_every) {
        std::cerr << m_what << ": " << status() << (m_label.empty() ? "" : "  " + m_label) << "\n";
        m_last_output = now;
        m_logged = true;
    }
}

void Progress::draw() {
    const int bar = 24;
    const int filled = m_total ? int(bar * std::min(m_done, m_total) / m_total) : 0;
    std::string line = m_what + " [" + std::string(size_t(filled), '#') +
                       std::string(size_t(bar - filled), '.') + "] " + std::to_string(m_done) +
                       "/" + std::to_string(m_total) + " " + m_unit + " ETA " + eta() +
                       (m_label.empty() ? "" : "  " + m_label);
    if (line.size() > 110) line.resize(110);
    std::cerr << "\r\033[K" << line << std::flush;
    m_drawn = true;
    m_last_output = HostClock::now();
}

void Progress::clear() {
    if (m_tty && m_drawn) std::cerr << "\r\033[K" << std::flush;
    m_drawn = false;
}

void Progress::log(const std::string& line) {
    clear();
    std::cerr << line << "\n";
    m_last_output = HostClock::now();
    if (m_tty && !m_finished) draw();
}

void Progress::finish() {
    if (m_finished) return;
    clear();
    if (!m_tty && m_logged) std::cerr << m_what << ": done " << status() << "\n";
    m_finished = true;
}

}  // namespace sfx
