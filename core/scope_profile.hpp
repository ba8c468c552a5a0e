#pragma once
// Wall time of named parts of a computation, for the simulator's --profile (docs/sim.md,
// "Profile"). A Scope adds the time from its construction to its end to its name's total.
// Off (not even a clock read) until set_enabled(true); then only the thread that enabled it
// records: the scopes sit around parallel regions, on the thread that opens them, never inside.
// Scopes nest; each total is inclusive of the scopes within it.
#include <string>
#include <vector>

namespace yarnhom::prof {

void set_enabled(bool on);
bool enabled();

class Scope {
 public:
  // name: a string literal (its address is the key: one entry per literal).
  explicit Scope(const char* name);
  ~Scope();
  Scope(const Scope&) = delete;
  Scope& operator=(const Scope&) = delete;

 private:
  int slot_ = -1;
  long long start_ns_ = -1;
};

// Adds seconds to name's total as one call (a time measured elsewhere: a parallel region's
// slowest thread).
void add(const char* name, double seconds);

struct Entry {
  std::string name;
  double seconds = 0;
  long calls = 0;
};
// The totals, in the order the names were first met.
std::vector<Entry> entries();
void reset();

}  // namespace yarnhom::prof
