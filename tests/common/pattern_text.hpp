#pragma once
// Editing one row of a pattern file's block as text (`*BLOCK` headers, one row per line), for the
// refusal tests (tests/tools) and the hardening campaign (tools/campaign).
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace yarnhom::test {

// The text with row `row` of block `block` replaced by edit(row's line). Rows count from 0 over
// the block's non-empty lines; comment lines ('#') count too unless skip_comments.
inline std::string edit_pattern_row(const std::string& text, const std::string& block, int row, bool skip_comments,
                                    const std::function<std::string(const std::string&)>& edit) {
  std::istringstream in(text);
  std::string out, l, cur;
  int k = -1;
  while (std::getline(in, l)) {
    if (!l.empty() && l[0] == '*') {
      std::istringstream hs(l.substr(1));
      hs >> cur;
      k = -1;
    } else if (cur == block && !l.empty() && !(skip_comments && l[0] == '#')) {
      if (++k == row) l = edit(l);
    }
    out += l + "\n";
  }
  return out;
}

// The line's whitespace-separated fields with field `field` (0-based) replaced by v, joined by
// single spaces (a field past the end: the line's fields unchanged).
inline std::string with_field(const std::string& line, int field, const std::string& v) {
  std::istringstream ls(line);
  std::vector<std::string> f;
  for (std::string x; ls >> x;) f.push_back(x);
  if (field < int(f.size())) f[field] = v;
  std::string out;
  for (auto& x : f) out += (out.empty() ? "" : " ") + x;
  return out;
}

}  // namespace yarnhom::test
