#include "core/model.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/h5.hpp"
#include "core/term_attrs.hpp"

namespace yarnhom {

const ModelNetwork* Model::find(const std::string& name) const { return find_term(networks, name); }

namespace {

void write_history(const h5::Node& g, const History& h) {
  const hsize_t n = h.size();
  g.write("train_loss", h.train_loss, {n});
  g.write("val_loss", h.val_loss, {n});
  g.write("lr", h.lr, {n});
  g.write("L_Z", h.loss_z, {n});
  g.write("L_F", h.loss_f, {n});
  g.write("L_C", h.loss_c, {n});
  g.write("L_S", h.loss_s, {n});
  if (!h.polish_train.empty()) {
    g.write("polish_train_loss", h.polish_train, {h.polish_train.size()});
    g.write("polish_val_loss", h.polish_val, {h.polish_val.size()});
  }
}

// Every curve has one value per epoch: their common length comes from train_loss's declared
// shape, and the others must declare the same before they are read.
History read_history(const h5::Node& g) {
  History h;
  const auto dims = g.shape("train_loss");
  if (dims.size() != 1) g.fail(g.child_path("train_loss"), "wrong shape " + h5::shape_string(dims) + ", expected [epochs]");
  const int64_t E = static_cast<int64_t>(dims[0]);
  h.train_loss = g.read_double("train_loss", {E}).data;
  h.val_loss = g.read_double("val_loss", {E}).data;
  h.lr = g.read_double("lr", {E}).data;
  h.loss_z = g.read_double("L_Z", {E}).data;
  h.loss_f = g.read_double("L_F", {E}).data;
  h.loss_c = g.read_double("L_C", {E}).data;
  h.loss_s = g.read_double("L_S", {E}).data;
  if (g.has("polish_train_loss")) h.polish_train = g.read_double("polish_train_loss").data;
  if (g.has("polish_val_loss")) h.polish_val = g.read_double("polish_val_loss").data;
  return h;
}

void check_number(const h5::Node& g, const char* what, double v, bool positive) {
  if (!std::isfinite(v) || (positive && !(v > 0)))
    g.fail(g.path(), std::string("attribute ") + what + " must be " + (positive ? "positive and finite" : "finite") +
                         ", is " + std::to_string(v));
}

}  // namespace

void write_model(const std::string& path, const Model& model) {
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path(), kModelFormat, kModelVersion);
    root.set_attr("dataset", model.dataset);
    root.set_attr("seed", static_cast<int64_t>(model.seed));
    if (!std::isnan(model.areal_density)) root.set_attr("areal_density", model.areal_density);
    h5::Node nets = root.create_group("networks");
    for (const ModelNetwork& n : model.networks) {
      h5::Node g = nets.create_group(n.term.name);
      write_box_attrs(g, n.term, n.lower, n.upper);
      write_network_attrs(g, n.desc, n.norm);
      g.set_attr("w_Z", n.weights.z);
      g.set_attr("w_F", n.weights.f);
      g.set_attr("w_C", n.weights.c);
      g.set_attr("w_S", n.weights.s);
      g.set_attr("w_X", n.weights.x);
      g.set_attr("epochs", n.epochs);
      g.set_attr("backend", n.backend);
      g.set_attr("status", n.status);
      if (!n.recipe.empty()) g.set_attr("recipe", n.recipe);
      if (!n.val_index.empty()) g.write("val_index", n.val_index, {n.val_index.size()});
      for (int k = 0; k < n.desc.num_layers(); ++k) {
        const hsize_t out_k = n.desc.layer_out(k), in_k = n.desc.layer_in(k);
        const float* w = n.params.data() + n.desc.weight_offset(k);
        const float* b = n.params.data() + n.desc.bias_offset(k);
        h5::Node l = g.create_group("layer" + std::to_string(k));
        l.write("W", std::vector<float>(w, w + out_k * in_k), {out_k, in_k});
        l.write("b", std::vector<float>(b, b + out_k), {out_k});
      }
      write_history(g.create_group("history"), n.history);
    }
  }
  out.commit();
}

Model read_model(const std::string& path) {
  h5::Node root = h5::open_file(path);
  if (!root.has_attr("format") || root.attr_string("format") != kModelFormat)
    root.fail("/", std::string("not a yarnhom model (attribute format must be '") + kModelFormat + "')");
  if (root.attr_int("version") != kModelVersion)
    root.fail("/", "unsupported model version " + std::to_string(root.attr_int("version")));
  Model m;
  m.dataset = root.attr_string("dataset");
  m.seed = static_cast<uint64_t>(root.attr_int("seed"));
  if (root.has_attr("areal_density")) {
    m.areal_density = root.attr_double("areal_density");
    if (!(m.areal_density > 0 && std::isfinite(m.areal_density)))
      root.fail("/", "areal_density must be positive and finite (absent when unknown)");
  }
  h5::Node nets = root.group("networks");
  // A network under a name that is no term would be dropped without a word: refuse it.
  for (const std::string& name : nets.children()) {
    try {
      term_by_name(name);
    } catch (const std::invalid_argument& e) {
      nets.fail("/networks/" + name, e.what());
    }
  }
  for (const Term& term : all_terms()) {
    if (!nets.has(term.name)) continue;
    h5::Node g = nets.group(term.name);
    ModelNetwork n;
    n.term = term;
    if (g.has_attr("indices") && g.attr_ints("indices") != term.indices)
      g.fail(g.path(), "attribute indices does not match the term name");
    n.lower = g.attr_doubles("lower");
    n.upper = g.attr_doubles("upper");
    n.desc.input_dim = term.dim();
    n.desc.hidden = g.attr_ints("hidden");
    n.desc.activation = g.attr_string("activation");
    try {
      n.desc.validate();
    } catch (const std::invalid_argument& e) {
      g.fail(g.path(), e.what());
    }
    n.norm.center = g.attr_doubles("in_center");
    n.norm.halfwidth = g.attr_doubles("in_halfwidth");
    n.norm.out_mean = g.attr_double("out_mean");
    n.norm.out_std = g.attr_double("out_std");
    const size_t d = term.dim();
    if (n.lower.size() != d || n.upper.size() != d || n.norm.center.size() != d ||
        n.norm.halfwidth.size() != d)
      g.fail(g.path(), "box or normalization attributes do not have " + std::to_string(d) + " entries");
    // The normalization maps the box to [-1, 1]^d and the energies to unit spread: a zero or
    // non-finite scale is a constant or broken model, not one to evaluate.
    for (size_t k = 0; k < d; ++k) {
      check_number(g, "lower", n.lower[k], false);
      check_number(g, "upper", n.upper[k], false);
      if (!(n.lower[k] < n.upper[k])) g.fail(g.path(), "empty box: lower must be below upper");
      check_number(g, "in_center", n.norm.center[k], false);
      check_number(g, "in_halfwidth", n.norm.halfwidth[k], true);
    }
    check_number(g, "out_mean", n.norm.out_mean, false);
    check_number(g, "out_std", n.norm.out_std, true);
    n.weights.z = g.attr_double("w_Z");
    n.weights.f = g.attr_double("w_F");
    n.weights.c = g.attr_double("w_C");
    n.weights.s = g.attr_double("w_S");
    n.weights.x = g.attr_double("w_X");
    const int64_t epochs = g.attr_int("epochs");
    if (epochs < 0 || epochs > 1000000000) g.fail(g.path(), "attribute epochs out of range: " + std::to_string(epochs));
    n.epochs = static_cast<int>(epochs);
    n.backend = g.attr_string("backend");
    n.status = g.attr_string("status");
    n.params.resize(n.desc.num_params());
    for (int k = 0; k < n.desc.num_layers(); ++k) {
      const std::string l = "layer" + std::to_string(k);
      const size_t out_k = n.desc.layer_out(k), in_k = n.desc.layer_in(k);
      auto w = g.read_float(l + "/W", {int64_t(out_k), int64_t(in_k)});
      auto b = g.read_float(l + "/b", {int64_t(out_k)});
      if (w.dims != std::vector<hsize_t>{out_k, in_k})
        g.fail(g.child_path(l + "/W"), "wrong shape: expected [" + std::to_string(out_k) + ", " +
                                           std::to_string(in_k) + "]");
      if (b.dims != std::vector<hsize_t>{out_k})
        g.fail(g.child_path(l + "/b"), "wrong shape: expected [" + std::to_string(out_k) + "]");
      std::copy(w.data.begin(), w.data.end(), n.params.begin() + n.desc.weight_offset(k));
      std::copy(b.data.begin(), b.data.end(), n.params.begin() + n.desc.bias_offset(k));
    }
    for (float p : n.params)
      if (!std::isfinite(p)) g.fail(g.path(), "non-finite weight");
    if (g.has("history")) n.history = read_history(g.group("history"));
    if (g.has_attr("recipe")) n.recipe = g.attr_string("recipe");
    if (g.has("val_index")) {
      n.val_index = g.read_int("val_index").data;
      for (int i : n.val_index)
        if (i < 0) g.fail(g.child_path("val_index"), "negative row index");
    }
    m.networks.push_back(std::move(n));
  }
  if (m.networks.empty()) nets.fail("/networks", "no networks");
  return m;
}

}  // namespace yarnhom
