// The registry of training backends: the names `--backend` takes and the factory behind each.
// The CUDA backend is listed only in builds that compiled it (YARNHOM_HAVE_CUDA).
#include <functional>
#include <stdexcept>
#include <utility>

#include "train/backend.hpp"
#include "train/cpu_backend.hpp"
#ifdef YARNHOM_HAVE_CUDA
#include "train/cuda_backend.hpp"
#endif

namespace yarnhom {

namespace {
using Factory = std::unique_ptr<Backend> (*)();
const std::vector<std::pair<std::string, Factory>>& registry() {
  static const std::vector<std::pair<std::string, Factory>> r = {
      {"cpu", &make_cpu_backend},
#ifdef YARNHOM_HAVE_CUDA
      {"cuda", &make_cuda_backend},
#endif
  };
  return r;
}
}  // namespace

std::vector<std::string> available_backends() {
  std::vector<std::string> names;
  for (const auto& [name, make] : registry()) names.push_back(name);
  return names;
}

std::unique_ptr<Backend> make_backend(const std::string& name) {
  for (const auto& [n, make] : registry())
    if (n == name) return make();
  std::string list;
  for (auto& b : available_backends()) list += (list.empty() ? "" : ", ") + b;
  throw std::invalid_argument("unknown or unavailable backend '" + name + "' (this build has: " + list + ")");
}

}  // namespace yarnhom
