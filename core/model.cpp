#include "core/model.hpp"

#include <cmath>

#include "core/atomic_file.hpp"
#include "core/h5.hpp"

namespace yarnhom {

const ModelNetwork* Model::find(const std::string& name) const {
  for (const ModelNetwork& n : networks)
    if (n.term.name == name) return &n;
  return nullptr;
}

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

History read_history(const h5::Node& g) {
  History h;
  h.train_loss = g.read_double("train_loss").data;
  h.val_loss = g.read_double("val_loss").data;
  h.lr = g.read_double("lr").data;
  h.loss_z = g.read_double("L_Z").data;
  h.loss_f = g.read_double("L_F").data;
  h.loss_c = g.read_double("L_C").data;
  h.loss_s = g.read_double("L_S").data;
  if (g.has("polish_train_loss")) h.polish_train = g.read_double("polish_train_loss").data;
  if (g.has("polish_val_loss")) h.polish_val = g.read_double("polish_val_loss").data;
  return h;
}

}  // namespace

void write_model(const std::string& path, const Model& model) {
  AtomicOutput out(path);
  {
    h5::Node root = h5::create_file(out.temp_path());
    root.set_attr("format", kModelFormat);
    root.set_attr("version", kModelVersion);
    root.set_attr("dataset", model.dataset);
    root.set_attr("seed", static_cast<int64_t>(model.seed));
    if (!std::isnan(model.areal_density)) root.set_attr("areal_density", model.areal_density);
    h5::Node nets = root.create_group("networks");
    for (const ModelNetwork& n : model.networks) {
      h5::Node g = nets.create_group(n.term.name);
      g.set_attr("indices", n.term.indices);
      g.set_attr("lower", n.lower);
      g.set_attr("upper", n.upper);
      g.set_attr("activation", n.desc.activation);
      g.set_attr("hidden", n.desc.hidden);
      g.set_attr("in_center", n.norm.center);
      g.set_attr("in_halfwidth", n.norm.halfwidth);
      g.set_attr("out_mean", n.norm.out_mean);
      g.set_attr("out_std", n.norm.out_std);
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
  for (const Term& term : all_terms()) {
    if (!nets.has(term.name)) continue;
    h5::Node g = nets.group(term.name);
    ModelNetwork n;
    n.term = term;
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
    n.weights.z = g.attr_double("w_Z");
    n.weights.f = g.attr_double("w_F");
    n.weights.c = g.attr_double("w_C");
    n.weights.s = g.attr_double("w_S");
    n.weights.x = g.attr_double("w_X");
    n.epochs = static_cast<int>(g.attr_int("epochs"));
    n.backend = g.attr_string("backend");
    n.status = g.attr_string("status");
    n.params.resize(n.desc.num_params());
    for (int k = 0; k < n.desc.num_layers(); ++k) {
      const std::string l = "layer" + std::to_string(k);
      auto w = g.read_float(l + "/W");
      auto b = g.read_float(l + "/b");
      const size_t out_k = n.desc.layer_out(k), in_k = n.desc.layer_in(k);
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
