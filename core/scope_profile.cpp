#include "core/scope_profile.hpp"

#include <chrono>
#include <thread>

namespace yarnhom::prof {

namespace {
struct Slot {
  const char* name;
  long long ns;
  long calls;
};
// One recording thread: no lock. A few dozen names: a linear search by address.
struct Registry {
  bool on = false;
  std::thread::id owner;
  std::vector<Slot> slots;
};
Registry& registry() {
  static Registry r;
  return r;
}
long long now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
bool recording() {
  const Registry& r = registry();
  return r.on && r.owner == std::this_thread::get_id();
}

int slot_of(const char* name) {
  std::vector<Slot>& slots = registry().slots;
  for (size_t k = 0; k < slots.size(); ++k)
    if (slots[k].name == name) return int(k);
  slots.push_back({name, 0, 0});  // registered when first met: a part before the parts nested in it
  return int(slots.size()) - 1;
}
}  // namespace

void set_enabled(bool on) {
  Registry& r = registry();
  r.on = on;
  r.owner = std::this_thread::get_id();
}

bool enabled() { return registry().on; }

Scope::Scope(const char* name) {
  if (!recording()) return;
  slot_ = slot_of(name);
  start_ns_ = now_ns();
}

void add(const char* name, double seconds) {
  if (!recording()) return;
  Slot& s = registry().slots[size_t(slot_of(name))];
  s.ns += (long long)(1e9 * seconds);
  ++s.calls;
}

Scope::~Scope() {
  if (start_ns_ < 0 || !recording() || slot_ >= int(registry().slots.size())) return;
  Slot& s = registry().slots[size_t(slot_)];
  s.ns += now_ns() - start_ns_;
  ++s.calls;
}

std::vector<Entry> entries() {
  std::vector<Entry> out;
  for (const Slot& s : registry().slots) out.push_back({s.name, 1e-9 * double(s.ns), s.calls});
  return out;
}

void reset() { registry().slots.clear(); }

}  // namespace yarnhom::prof
