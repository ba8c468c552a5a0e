#include "produce/produce_checkpoint.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "core/error.hpp"

namespace yarnhom::yarn {

namespace {

constexpr char kMagic[] = "yarnhom-produce-checkpoint ";
constexpr char kRecord[4] = {'Y', 'R', 'E', 'C'};

uint64_t fnv1a(const char* p, size_t n, uint64_t h = 1469598103934665603ull) {
  for (size_t i = 0; i < n; ++i) {
    h ^= static_cast<unsigned char>(p[i]);
    h *= 1099511628211ull;
  }
  return h;
}

// The record payload: plain values in the machine's layout, vectors with their length first.
// Vectors of the stored state that are bit for bit those of a reference (the frames: the rest
// state's, which no solve changes; the anchor: the state's own u after a solve) are written as
// a flag alone, which keeps a record near 4 doubles per vertex and term axis.
struct Out {
  std::string b;
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    b.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void doubles(const double* p, size_t n) {
    put(static_cast<uint64_t>(n));
    b.append(reinterpret_cast<const char*>(p), n * sizeof(double));
  }
  void str(const std::string& s) {
    put(static_cast<uint64_t>(s.size()));
    b += s;
  }
  // A vector, or the flag 1 when it equals `ref` bit for bit.
  void doubles_or_same(const std::vector<double>& v, const std::vector<double>* ref) {
    const bool same = ref && ref->size() == v.size() &&
                      (v.empty() || std::memcmp(v.data(), ref->data(), v.size() * sizeof(double)) == 0);
    put(static_cast<uint8_t>(same));
    if (!same) doubles(v.data(), v.size());
  }
};

struct In {
  const char* p;
  const char* end;
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    need(sizeof v);
    std::memcpy(&v, p, sizeof v);
    p += sizeof v;
    return v;
  }
  void need(size_t n) const {
    if (static_cast<size_t>(end - p) < n) throw std::runtime_error("record shorter than its contents");
  }
  std::vector<double> doubles() {
    const uint64_t n = get<uint64_t>();
    if (n > static_cast<uint64_t>(end - p) / sizeof(double)) throw std::runtime_error("vector longer than its record");
    std::vector<double> v(n);
    if (n) std::memcpy(v.data(), p, n * sizeof(double));
    p += n * sizeof(double);
    return v;
  }
  std::string str() {
    const uint64_t n = get<uint64_t>();
    if (n > static_cast<uint64_t>(end - p)) throw std::runtime_error("text longer than its record");
    std::string s(p, n);
    p += n;
    return s;
  }
  std::vector<double> doubles_or_same(const std::vector<double>& ref) { return get<uint8_t>() ? ref : doubles(); }
};

std::vector<double> flat(const std::vector<Eigen::Vector3d>& v) {
  std::vector<double> f(3 * v.size());
  for (size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k) f[3 * i + k] = v[i][k];
  return f;
}
std::vector<Eigen::Vector3d> unflat(const std::vector<double>& f) {
  if (f.size() % 3) throw std::runtime_error("a list of 3-vectors with " + std::to_string(f.size()) + " values");
  std::vector<Eigen::Vector3d> v(f.size() / 3);
  for (size_t i = 0; i < v.size(); ++i) v[i] = Eigen::Vector3d(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
  return v;
}
std::vector<double> flat(const std::vector<EdgeFrame>& e) {
  std::vector<double> f;
  f.reserve(6 * e.size());
  for (const EdgeFrame& x : e) f.insert(f.end(), {x.t[0], x.t[1], x.t[2], x.d1[0], x.d1[1], x.d1[2]});
  return f;
}
std::vector<EdgeFrame> unflat_frames(const std::vector<double>& f) {
  if (f.size() % 6) throw std::runtime_error("edge frames with " + std::to_string(f.size()) + " values");
  std::vector<EdgeFrame> e(f.size() / 6);
  for (size_t i = 0; i < e.size(); ++i)
    e[i] = {Eigen::Vector3d(f[6 * i], f[6 * i + 1], f[6 * i + 2]), Eigen::Vector3d(f[6 * i + 3], f[6 * i + 4], f[6 * i + 5])};
  return e;
}
void put_strain(Out& o, const Strain& s) {
  for (int k = 0; k < 6; ++k) o.put(s[k]);
}
Strain get_strain(In& in) {
  Strain s;
  for (int k = 0; k < 6; ++k) s[k] = in.get<double>();
  return s;
}

std::string encode(const CheckpointRecord& r, const RveState& rest) {
  Out o;
  o.put(static_cast<int32_t>(r.term));
  o.put(static_cast<int32_t>(r.index));
  o.put(static_cast<int32_t>(r.iterations));
  o.put(r.seconds);
  o.put(r.cpu_seconds);
  o.str(r.status);
  o.put(r.psi);
  put_strain(o, r.grad);
  o.put(r.min_distance);
  o.put(static_cast<uint8_t>(r.has_state));
  if (r.has_state) {
    const RveState& s = r.state;
    const std::vector<double> u = flat(s.u);
    o.doubles(u.data(), u.size());
    o.doubles(s.theta.data(), s.theta.size());
    const std::vector<double> rest_edges = flat(rest.frames.edge);
    o.doubles_or_same(flat(s.frames.edge), &rest_edges);
    o.doubles_or_same(s.frames.twist, &rest.frames.twist);
    const ContactCertificate& c = s.certificate;
    o.put(c.dmin);
    o.put(static_cast<uint8_t>(c.valid));
    o.put(c.min_distance);
    o.put(static_cast<int32_t>(c.moves));
    o.str(c.failure);
    put_strain(o, s.anchor.s);
    o.doubles_or_same(flat(s.anchor.u), &u);
    o.put(static_cast<uint64_t>(s.path.size()));
    for (const PathPoint& p : s.path) {
      put_strain(o, p.s);
      const std::vector<double> pu = flat(p.u);
      o.doubles(pu.data(), pu.size());
    }
    o.put(static_cast<uint64_t>(r.sensitivity.size()));
    for (const Eigen::VectorXd& v : r.sensitivity) o.doubles(v.data(), v.size());
  }
  return o.b;
}

CheckpointRecord decode(const char* p, size_t n, const RveState& rest) {
  In in{p, p + n};
  CheckpointRecord r;
  r.term = in.get<int32_t>();
  r.index = in.get<int32_t>();
  r.iterations = in.get<int32_t>();
  r.seconds = in.get<double>();
  r.cpu_seconds = in.get<double>();
  r.status = in.str();
  r.psi = in.get<double>();
  r.grad = get_strain(in);
  r.min_distance = in.get<double>();
  r.has_state = in.get<uint8_t>() != 0;
  if (r.has_state) {
    RveState& s = r.state;
    const std::vector<double> u = in.doubles();
    s.u = unflat(u);
    s.theta = in.doubles();
    s.frames.edge = unflat_frames(in.doubles_or_same(flat(rest.frames.edge)));
    s.frames.twist = in.doubles_or_same(rest.frames.twist);
    const size_t nv = rest.u.size();
    if (s.u.size() != nv || s.theta.size() != rest.theta.size() || s.frames.edge.size() != rest.frames.edge.size() ||
        s.frames.twist.size() != rest.frames.twist.size())
      throw std::runtime_error("state of " + std::to_string(s.u.size()) + " vertices, the pattern has " + std::to_string(nv));
    ContactCertificate& c = s.certificate;
    c.dmin = in.get<double>();
    c.valid = in.get<uint8_t>() != 0;
    c.min_distance = in.get<double>();
    c.moves = in.get<int32_t>();
    c.failure = in.str();
    s.anchor.s = get_strain(in);
    s.anchor.u = unflat(in.doubles_or_same(u));
    if (s.anchor.u.size() != nv) throw std::runtime_error("anchor of another vertex count");
    const uint64_t np = in.get<uint64_t>();
    if (np > n) throw std::runtime_error("path longer than its record");
    for (uint64_t i = 0; i < np; ++i) {
      PathPoint pp;
      pp.s = get_strain(in);
      pp.u = unflat(in.doubles());
      if (pp.u.size() != nv) throw std::runtime_error("path point of another vertex count");
      s.path.push_back(std::move(pp));
    }
    const uint64_t ns = in.get<uint64_t>();
    if (ns > 2) throw std::runtime_error(std::to_string(ns) + " sensitivities (a term has at most 2 axes)");
    for (uint64_t i = 0; i < ns; ++i) {
      const std::vector<double> v = in.doubles();
      r.sensitivity.push_back(Eigen::Map<const Eigen::VectorXd>(v.data(), v.size()));
    }
  }
  if (in.p != in.end) throw std::runtime_error("bytes left over after its contents");
  return r;
}

// What differs between two runs' first lines, in words: the tokens between their common
// leading and trailing ones (a changed setting is one token, "branch=12/0.05/direct40"; a
// changed term list is several), so that a refusal names the setting instead of a list of
// candidates.
std::string describe_difference(const std::string& have, const std::string& want) {
  auto split = [](const std::string& s) {
    std::vector<std::string> t;
    std::istringstream in(s);
    for (std::string w; in >> w;) t.push_back(w);
    return t;
  };
  const std::vector<std::string> a = split(have), b = split(want);
  size_t pre = 0;
  while (pre < a.size() && pre < b.size() && a[pre] == b[pre]) ++pre;
  size_t suf = 0;
  while (suf < a.size() - pre && suf < b.size() - pre && a[a.size() - 1 - suf] == b[b.size() - 1 - suf]) ++suf;
  auto middle = [&](const std::vector<std::string>& t) {
    std::string m;
    for (size_t i = pre; i + suf < t.size(); ++i) m += (m.empty() ? "" : " ") + t[i];
    if (m.size() > 160) m = m.substr(0, 157) + "...";
    return m.empty() ? std::string("nothing") : "'" + m + "'";
  };
  return "it has " + middle(a) + " where this run has " + middle(b);
}

std::string header(const std::string& fingerprint, const std::string& rest_sig) {
  return kMagic + std::to_string(kCheckpointVersion) + " " + fingerprint + "\nrest " + rest_sig + "\n";
}

}  // namespace

std::string encode_record(const CheckpointRecord& r, const RveState& rest) { return encode(r, rest); }
CheckpointRecord decode_record(const std::string& bytes, const RveState& rest) {
  return decode(bytes.data(), bytes.size(), rest);
}

std::string rest_signature(double psi0, const RveState& rest) {
  uint64_t h = fnv1a(nullptr, 0);
  auto add = [&](const std::vector<double>& v) { h = fnv1a(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(double), h); };
  add(flat(rest.u));
  add(rest.theta);
  add(flat(rest.frames.edge));
  add(rest.frames.twist);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a %016" PRIx64, psi0, h);
  return buf;
}

namespace {

// Reads the record at `at`: false when it is not whole (cut by a kill) or fails its checksum.
bool read_record(std::ifstream& in, std::uintmax_t at, std::uintmax_t file_size, std::string& payload) {
  constexpr std::uintmax_t frame = sizeof kRecord + 2 * sizeof(uint64_t);
  if (file_size < at || file_size - at < frame) return false;
  char head[4 + sizeof(uint64_t)];
  in.clear();
  in.seekg(static_cast<std::streamoff>(at));
  if (!in.read(head, sizeof head) || std::memcmp(head, kRecord, 4) != 0) return false;
  uint64_t n, h;
  std::memcpy(&n, head + 4, sizeof n);
  if (n > file_size - at - frame) return false;
  payload.resize(n);
  if (!in.read(payload.data(), static_cast<std::streamsize>(n)) || !in.read(reinterpret_cast<char*>(&h), sizeof h))
    return false;
  return h == fnv1a(payload.data(), n);
}

}  // namespace

CheckpointContents read_checkpoint(const std::string& path, const std::string& fingerprint,
                                   const std::string& rest_sig, const RveState& rest) {
  CheckpointContents c;
  std::ifstream in(path, std::ios::binary);
  if (!in) return c;  // none yet
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw FileError(path, "", "cannot read the checkpoint's size: " + ec.message());
  const std::string want = header(fingerprint, rest_sig);
  std::string head(std::min<std::uintmax_t>(size, want.size()), '\0');
  if (!in.read(head.data(), static_cast<std::streamsize>(head.size())))
    throw FileError(path, "", "cannot read the checkpoint");
  // A file cut inside (or right after creating) its header holds no sample: start fresh.
  if (size < want.size() && want.compare(0, head.size(), head) == 0) return c;
  // The first line, whatever its length (up to the header's, which is all a checkpoint of
  // this run can have there).
  const std::string line1 = head.substr(0, head.find('\n'));
  if (line1.rfind(kMagic, 0) != 0)
    throw FileError(path, "line 1", "not a yarnhom produce checkpoint; remove it (or choose another -o) to start over");
  const size_t v0 = sizeof kMagic - 1;
  const std::string version = line1.substr(v0, line1.find(' ', v0) - v0);
  if (version != std::to_string(kCheckpointVersion))
    throw FileError(path, "line 1",
                    "checkpoint of format " + version + " (an older yarnhom: finished samples without their equilibrium "
                    "states, from which a resumed run cannot continue exactly as an uninterrupted one); remove it to "
                    "start over");
  const size_t eol = want.find('\n') + 1;
  if (head.compare(0, eol, want, 0, eol) != 0)
    throw FileError(path, "line 1",
                    "checkpoint of a different run: " + describe_difference(line1, want.substr(0, eol - 1)) +
                        " (pattern, preset, tolerance, terms, sectors, warm start, branch pass, ranges and material "
                        "must match); remove it to start over");
  if (head != want)
    throw FileError(path, "line 2",
                    "checkpoint of a different rest state (another build of yarnhom, or another thread count in the rest "
                    "relaxation): its samples cannot be continued bit for bit; remove it to start over");
  c.empty = false;
  std::uintmax_t at = want.size();
  std::string payload;
  // Stop at the first record that is not whole: only a kill cuts one, and only the last.
  for (int k = 1; read_record(in, at, size, payload); ++k) {
    try {
      CheckpointRecord r = decode(payload.data(), payload.size(), rest);
      // The state is read again when a child needs it (read_checkpoint_state): a long run's
      // states would not all fit in memory at once.
      r.state = RveState{};
      r.sensitivity.clear();
      r.offset = at;
      c.records.push_back(std::move(r));
    } catch (const std::exception& e) {
      // Whole and with the right checksum, yet not what this run writes.
      throw FileError(path, "record " + std::to_string(k), std::string(e.what()) + "; remove it to start over");
    }
    at += sizeof kRecord + 2 * sizeof(uint64_t) + payload.size();
  }
  c.valid_bytes = at;
  c.dropped_bytes = size - at;
  return c;
}

void read_checkpoint_state(const std::string& path, const RveState& rest, CheckpointRecord& r) {
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  std::string payload;
  if (!in || ec || !read_record(in, r.offset, size, payload))
    throw FileError(path, "", "the record at byte " + std::to_string(r.offset) + " can no longer be read");
  CheckpointRecord full = decode(payload.data(), payload.size(), rest);
  if (full.term != r.term || full.index != r.index || !full.has_state)
    throw FileError(path, "", "the record at byte " + std::to_string(r.offset) + " changed since it was read");
  r.state = std::move(full.state);
  r.sensitivity = std::move(full.sensitivity);
}

std::FILE* open_checkpoint(const std::string& path, const std::string& fingerprint, const std::string& rest_sig,
                           const CheckpointContents* resume) {
  std::FILE* f = nullptr;
  if (resume && !resume->empty) {
    if (resume->dropped_bytes) {
      std::error_code ec;
      std::filesystem::resize_file(path, resume->valid_bytes, ec);
      if (ec) throw FileError(path, "", "cannot remove the record cut by the kill: " + ec.message());
    }
    f = std::fopen(path.c_str(), "ab");
  } else {
    f = std::fopen(path.c_str(), "wb");
    if (f) {
      const std::string h = header(fingerprint, rest_sig);
      std::fwrite(h.data(), 1, h.size(), f);
    }
  }
  if (!f) throw FileError(path, "", "cannot open the checkpoint for writing");
  if (std::fflush(f) != 0) {
    std::fclose(f);
    throw FileError(path, "", "cannot write the checkpoint");
  }
  return f;
}

void append_checkpoint(std::FILE* f, const std::string& path, const CheckpointRecord& r, const RveState& rest) {
  const std::string payload = encode(r, rest);
  const uint64_t n = payload.size(), h = fnv1a(payload.data(), payload.size());
  std::string rec(kRecord, 4);
  rec.append(reinterpret_cast<const char*>(&n), sizeof n);
  rec += payload;
  rec.append(reinterpret_cast<const char*>(&h), sizeof h);
  if (std::fwrite(rec.data(), 1, rec.size(), f) != rec.size() || std::fflush(f) != 0)
    throw FileError(path, "", "cannot append to the checkpoint (disk full?)");
}

}  // namespace yarnhom::yarn
