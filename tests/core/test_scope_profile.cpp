// core/scope_profile: scopes add their wall time under their name, only when enabled and only
// on the thread that enabled them; nested scopes each count their own time.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/scope_profile.hpp"

namespace yarnhom {
namespace {

const prof::Entry* find(const std::vector<prof::Entry>& e, const std::string& name) {
  for (const prof::Entry& x : e)
    if (x.name == name) return &x;
  return nullptr;
}

TEST(ScopeProfile, RecordsNestedScopesOnTheEnablingThreadOnly) {
  prof::reset();
  prof::set_enabled(false);
  { prof::Scope s("off"); }
  EXPECT_TRUE(prof::entries().empty());
  prof::set_enabled(true);
  for (int k = 0; k < 2; ++k) {
    prof::Scope outer("outer");
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    prof::Scope inner("inner");
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  std::thread([] { prof::Scope s("other thread"); }).join();
  prof::set_enabled(false);
  const std::vector<prof::Entry> e = prof::entries();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].name, "outer");  // first met first
  const prof::Entry* outer = find(e, "outer");
  const prof::Entry* inner = find(e, "inner");
  ASSERT_TRUE(outer && inner);
  EXPECT_EQ(outer->calls, 2);
  EXPECT_EQ(inner->calls, 2);
  EXPECT_GE(inner->seconds, 0.006);
  EXPECT_GE(outer->seconds, inner->seconds + 0.004);  // inclusive of the nested scope
  EXPECT_EQ(find(e, "other thread"), nullptr);
  prof::reset();
  EXPECT_TRUE(prof::entries().empty());
}

}  // namespace
}  // namespace yarnhom
