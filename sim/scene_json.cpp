#include "sim/scene_json.hpp"

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>

#include "io/json_reader.hpp"
#include "sim/garment.hpp"
#include "sim/obj_io.hpp"
#include "sim/rectangle.hpp"

namespace yarnhom::sim {

namespace {

using json = io::json;

constexpr double kMaxRectangleQuads = 4e6;  // 2000 x 2000, the built-in scenes' largest --resolution

struct Reader : io::JsonReader {
  // An object whose keys are exactly `a` and `b`.
  const json& both(const json& j, const std::string& key, const char* a, const char* b) const {
    only(j, key, {a, b});
    if (!j.contains(a) || !j.contains(b)) fail(key, std::string("needs ") + a + " and " + b);
    return j;
  }
  std::vector<int> select(const json& j, const std::string& key, const Mesh& m) const {
    only(j, key, {"vertices", "rest_box"});
    std::vector<int> out;
    if (j.contains("vertices")) {
      const json& v = j["vertices"];
      if (!v.is_array()) fail(key + ".vertices", "must be an array of vertex indices");
      for (const json& i : v) {
        const int k = integer(i, key + ".vertices", 0);
        if (k >= m.num_vertices())
          fail(key + ".vertices", "vertex " + std::to_string(k) + " out of range (" + std::to_string(m.num_vertices()) + " vertices)");
        out.push_back(k);
      }
    }
    if (j.contains("rest_box")) {
      const json& b = j["rest_box"];
      if (!b.is_array() || b.size() != 4) fail(key + ".rest_box", "must be [u0, v0, u1, v1]");
      const double u0 = number(b[0], key), v0 = number(b[1], key), u1 = number(b[2], key), v1 = number(b[3], key);
      const double tol = 1e-9 * (1 + m.rest.cwiseAbs().maxCoeff());
      for (int v = 0; v < m.num_vertices(); ++v)
        if (m.rest(v, 0) >= u0 - tol && m.rest(v, 0) <= u1 + tol && m.rest(v, 1) >= v0 - tol && m.rest(v, 1) <= v1 + tol)
          out.push_back(v);
      if (out.empty()) fail(key + ".rest_box", "selects no vertex");
    }
    if (out.empty()) fail(key, "selects no vertex (give vertices or rest_box)");
    return out;
  }
};

// "mesh" (an OBJ file or a rectangle) and "position" (a rigid placement of it).
// A garment: {"garment": "tshirt", "resolution": k, "mannequin": false} (sim/garment.hpp).
void read_garment(const Reader& r, const json& jm, const json& j, Scene& s) {
  if (jm.contains("obj") || jm.contains("rectangle")) r.fail("mesh", "give one of obj, rectangle and garment");
  if (!jm["garment"].is_string() || jm["garment"] != "tshirt") r.fail("mesh.garment", "must be \"tshirt\" (the one garment built in)");
  const int k = jm.contains("resolution") ? r.integer(jm["resolution"], "mesh.resolution", 1) : 4;
  if (k > 80) r.fail("mesh.resolution", "must be between 1 and 80 (grid spacing 8 cm / resolution)");
  // The body stands in the mannequin's frame (sim/garment.hpp): the garment is not moved.
  if (j.contains("position"))
    r.fail("position", "a garment starts where the program places it; move the body instead (the mesh collider's "
                       "\"scale\" and \"translate\")");
  const std::string name = s.name;
  s = tshirt_garment(k);
  s.name = name;
  if (jm.contains("mannequin")) {
    if (!jm["mannequin"].is_boolean()) r.fail("mesh.mannequin", "must be true or false");
    if (jm["mannequin"].get<bool>()) s.obstacles.capsules = mannequin_capsules();
  }
}

void read_mesh(const Reader& r, const json& j, Scene& s) {
  if (!j.contains("mesh")) r.fail("mesh", "missing (give {\"obj\": FILE}, {\"rectangle\": {...}} or {\"garment\": \"tshirt\"})");
  const json& jm = j["mesh"];
  r.only(jm, "mesh", {"obj", "rectangle", "garment", "resolution", "mannequin"});
  if (!jm.contains("garment"))
    for (const char* k : {"resolution", "mannequin"})
      if (jm.contains(k)) r.fail(std::string("mesh.") + k, "applies to a garment only (\"garment\": \"tshirt\")");
  if (jm.contains("garment")) {
    read_garment(r, jm, j, s);
    return;
  }
  if (jm.contains("obj")) {
    const std::string obj = r.path(jm["obj"], "mesh.obj");
    try {
      s.mesh = read_obj(obj);
    } catch (const std::exception& e) {  // names the OBJ file: say which scene and key named it
      r.fail("mesh.obj", e.what());
    }
  } else if (jm.contains("rectangle")) {
    const json& rc = jm["rectangle"];
    r.only(rc, "mesh.rectangle", {"width", "height", "nx", "ny"});
    for (const char* k : {"width", "height", "nx", "ny"})
      if (!rc.contains(k)) r.fail(std::string("mesh.rectangle.") + k, "missing");
    const double width = r.positive(rc["width"], "mesh.rectangle.width"), height = r.positive(rc["height"], "mesh.rectangle.height");
    const int nx = r.integer(rc["nx"], "mesh.rectangle.nx", 1), ny = r.integer(rc["ny"], "mesh.rectangle.ny", 1);
    // Bounded before anything is allocated (1e8 x 1e8 quads ran out of memory).
    if (double(nx) * double(ny) > kMaxRectangleQuads)
      r.fail("mesh.rectangle", "nx x ny = " + std::to_string(nx) + " x " + std::to_string(ny) + " quads; at most " +
                                   std::to_string(long(kMaxRectangleQuads)) + " (nx ny <= 4e6, 8 million triangles)");
    s.mesh = make_rectangle(width, height, nx, ny);
  } else {
    r.fail("mesh", "give {\"obj\": FILE}, {\"rectangle\": {...}} or {\"garment\": \"tshirt\"}");
  }
  if (j.contains("position")) {
    const json& p = j["position"];
    r.only(p, "position", {"rotate_deg", "translate"});
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    if (p.contains("rotate_deg")) {
      const Eigen::Vector3d a = r.vec3(p["rotate_deg"], "position.rotate_deg") * (M_PI / 180);
      R = (Eigen::AngleAxisd(a.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(a.y(), Eigen::Vector3d::UnitY()) *
           Eigen::AngleAxisd(a.x(), Eigen::Vector3d::UnitX())).toRotationMatrix();
    }
    if (p.contains("translate")) t = r.vec3(p["translate"], "position.translate");
    for (int v = 0; v < s.mesh.num_vertices(); ++v) s.mesh.x.row(v) = (R * s.mesh.x.row(v).transpose() + t).transpose();
  }
}

// "pins" (handle 0 when given) and "handles" (selections with keyframed paths).
void read_handles(const Reader& r, const json& j, Scene& s) {
  if (j.contains("pins")) {
    if (!j["pins"].is_array()) r.fail("pins", "must be an array of selections");
    Handle h;
    for (size_t k = 0; k < j["pins"].size(); ++k) {
      auto v = r.select(j["pins"][k], "pins[" + std::to_string(k) + "]", s.mesh);
      h.vertices.insert(h.vertices.end(), v.begin(), v.end());
    }
    s.handles.push_back(h);
  }
  if (j.contains("handles")) {
    if (!j["handles"].is_array()) r.fail("handles", "must be an array");
    for (size_t k = 0; k < j["handles"].size(); ++k) {
      const std::string key = "handles[" + std::to_string(k) + "]";
      const json& jh = j["handles"][k];
      r.only(jh, key, {"select", "path"});
      if (!jh.contains("select")) r.fail(key + ".select", "missing");
      Handle h;
      h.vertices = r.select(jh["select"], key + ".select", s.mesh);
      if (jh.contains("path")) {
        const json& p = jh["path"];
        if (!p.is_array() || p.empty()) r.fail(key + ".path", "must be a non-empty array of [t, dx, dy, dz]");
        for (const json& kf : p) {
          if (!kf.is_array() || kf.size() != 4) r.fail(key + ".path", "each keyframe must be [t, dx, dy, dz]");
          std::array<double, 4> a;
          for (int i = 0; i < 4; ++i) a[i] = r.number(kf[i], key + ".path");
          if (!h.path.empty() && !(a[0] > h.path.back()[0])) r.fail(key + ".path", "keyframe times must increase");
          h.path.push_back(a);
        }
      }
      s.handles.push_back(h);
    }
  }
}

// A keyframe path [[t, dx, dy, dz], ...] with increasing times.
std::vector<std::array<double, 4>> read_path(const Reader& r, const json& p, const std::string& key) {
  if (!p.is_array() || p.empty()) r.fail(key, "must be a non-empty array of [t, dx, dy, dz]");
  std::vector<std::array<double, 4>> out;
  for (const json& kf : p) {
    if (!kf.is_array() || kf.size() != 4) r.fail(key, "each keyframe must be [t, dx, dy, dz]");
    std::array<double, 4> a;
    for (int i = 0; i < 4; ++i) a[i] = r.number(kf[i], key);
    if (!out.empty() && !(a[0] > out.back()[0])) r.fail(key, "keyframe times must increase");
    out.push_back(a);
  }
  return out;
}

// A capsule {"a", "b", "radius", "path"} or a mesh collider {"obj" | "frames", "frame_dt", "scale",
// "translate"} (sim/obstacles.hpp); friction < 0: the global one (set later).
void read_obstacle(const Reader& r, const json& jc, const std::string& key, double friction, bool garment, Scene& s) {
  if (jc.contains("capsule")) {
    const json& c = jc["capsule"];
    const std::string k = key + ".capsule";
    r.only(c, k, {"a", "b", "radius", "path"});
    for (const char* need : {"a", "b", "radius"})
      if (!c.contains(need)) r.fail(k + "." + need, "missing");
    CapsuleObstacle cap;
    cap.a = r.vec3(c["a"], k + ".a");
    cap.b = r.vec3(c["b"], k + ".b");
    if (!((cap.b - cap.a).norm() > 0)) r.fail(k + ".b", "must differ from a (a capsule's axis has a length)");
    cap.radius = r.positive(c["radius"], k + ".radius");
    if (c.contains("path")) cap.path = read_path(r, c["path"], k + ".path");
    cap.friction = friction;
    s.obstacles.capsules.push_back(cap);
    return;
  }
  const json& m = jc["mesh"];
  const std::string k = key + ".mesh";
  r.only(m, k, {"obj", "frames", "frame_dt", "scale", "translate"});
  std::vector<std::string> files;
  if (m.contains("obj") == m.contains("frames")) r.fail(k, "give obj (a static mesh) or frames (a list of OBJ files)");
  if (m.contains("obj")) files.push_back(r.path(m["obj"], k + ".obj"));
  if (m.contains("frames")) {
    if (!m["frames"].is_array() || m["frames"].empty()) r.fail(k + ".frames", "must be a non-empty array of OBJ files");
    for (const json& f : m["frames"]) files.push_back(r.path(f, k + ".frames"));
  }
  const double dt = m.contains("frame_dt") ? r.positive(m["frame_dt"], k + ".frame_dt") : 1.0 / 30;
  const double scale = m.contains("scale") ? r.positive(m["scale"], k + ".scale") : 1.0;
  const Eigen::Vector3d off = m.contains("translate") ? r.vec3(m["translate"], k + ".translate") : Eigen::Vector3d::Zero();
  try {
    MeshObstacle mo = read_mesh_obstacle(files, dt, scale, off);
    if (garment) check_body_clear_of_tshirt(mo);
    mo.friction = friction;
    s.obstacles.meshes.push_back(std::move(mo));
  } catch (const std::invalid_argument& e) {
    r.fail(k, e.what());
  }
}

// "colliders", "barrier", "friction" and "self_collision".
void read_contact(const Reader& r, const json& j, bool garment, Scene& s) {
  if (j.contains("colliders")) {
    if (!j["colliders"].is_array()) r.fail("colliders", "must be an array");
    for (size_t k = 0; k < j["colliders"].size(); ++k) {
      const std::string key = "colliders[" + std::to_string(k) + "]";
      const json& jc = j["colliders"][k];
      r.only(jc, key, {"sphere", "plane", "capsule", "mesh", "friction"});
      Collider c;
      c.friction = -1;  // none of its own: the global "friction" (below), else 0
      if (jc.contains("friction")) c.friction = r.nonnegative(jc["friction"], key + ".friction");
      if (jc.contains("capsule") || jc.contains("mesh")) {
        read_obstacle(r, jc, key, c.friction, garment, s);
        continue;
      }
      if (jc.contains("sphere")) {
        const json& sp = r.both(jc["sphere"], key + ".sphere", "center", "radius");
        c.kind = Collider::Kind::Sphere;
        c.center = r.vec3(sp["center"], key + ".sphere.center");
        c.radius = r.positive(sp["radius"], key + ".sphere.radius");
      } else if (jc.contains("plane")) {
        const json& pl = r.both(jc["plane"], key + ".plane", "point", "normal");
        c.kind = Collider::Kind::Plane;
        c.center = r.vec3(pl["point"], key + ".plane.point");
        c.normal = r.vec3(pl["normal"], key + ".plane.normal");
        if (!(c.normal.norm() > 0)) r.fail(key + ".plane.normal", "must be non-zero");
        c.normal.normalize();
      } else {
        r.fail(key, "give sphere or plane");
      }
      s.colliders.push_back(c);
    }
  }
  if (j.contains("barrier")) {
    r.only(j["barrier"], "barrier", {"dhat", "kappa"});
    if (j["barrier"].contains("dhat")) s.dhat = r.positive(j["barrier"]["dhat"], "barrier.dhat");
    if (j["barrier"].contains("kappa")) s.kappa = r.positive(j["barrier"]["kappa"], "barrier.kappa");
  }
  // Friction: one coefficient for every collider without its own, as a number or with the
  // sticking velocity and the lag updates (sim/friction.hpp).
  double mu = 0;
  if (j.contains("friction")) {
    const json& f = j["friction"];
    if (f.is_number()) {
      mu = r.nonnegative(f, "friction");
    } else {
      if (!f.is_object()) r.fail("friction", "must be a coefficient (number >= 0) or {\"mu\", \"eps_v\", \"updates\"}");
      r.only(f, "friction", {"mu", "eps_v", "updates"});
      if (f.contains("mu")) mu = r.nonnegative(f["mu"], "friction.mu");
      if (f.contains("eps_v")) s.friction_eps_v = r.positive(f["eps_v"], "friction.eps_v");
      if (f.contains("updates")) s.friction_updates = r.integer(f["updates"], "friction.updates", 0);
    }
  }
  for (Collider& c : s.colliders)
    if (c.friction < 0) c.friction = mu;
  for (CapsuleObstacle& c : s.obstacles.capsules)
    if (c.friction < 0) c.friction = mu;
  for (MeshObstacle& m : s.obstacles.meshes)
    if (m.friction < 0) m.friction = mu;
  // Self-collision: true | false | {"enabled": bool, "friction": mu} (default on, friction the global one).
  s.self_friction = mu;
  if (j.contains("self_collision")) {
    const json& sc = j["self_collision"];
    if (sc.is_boolean()) {
      s.self_collision = sc.get<bool>();
    } else {
      if (!sc.is_object()) r.fail("self_collision", "must be true, false or {\"enabled\": bool, \"friction\": mu}");
      r.only(sc, "self_collision", {"enabled", "friction"});
      if (sc.contains("enabled")) {
        if (!sc["enabled"].is_boolean()) r.fail("self_collision.enabled", "must be true or false");
        s.self_collision = sc["enabled"].get<bool>();
      }
      if (sc.contains("friction")) s.self_friction = r.nonnegative(sc["friction"], "self_collision.friction");
    }
  }
}

// "seams": {"stitches": [[a, b], ...], "stiffness": N/m, "sew_time": s, "gravity_delay": s}.
void read_seams(const Reader& r, const json& j, Scene& s) {
  if (!j.contains("seams")) return;
  const json& sm = j["seams"];
  r.only(sm, "seams", {"stitches", "stiffness", "sew_time", "gravity_delay"});
  // A garment brings its stitches: the file's are added to them (and may be left out).
  const bool garment = !s.stitches.empty();
  const json none = json::array();
  if ((!garment || sm.contains("stitches")) && (!sm.contains("stitches") || !sm["stitches"].is_array() || sm["stitches"].empty()))
    r.fail("seams.stitches", "must be a non-empty array of [a, b] vertex pairs");
  for (const json& p : sm.contains("stitches") ? sm["stitches"] : none) {
    if (!p.is_array() || p.size() != 2) r.fail("seams.stitches", "each stitch must be [a, b] (two vertex indices)");
    const int a = r.integer(p[0], "seams.stitches", 0), b = r.integer(p[1], "seams.stitches", 0);
    for (int v : {a, b})
      if (v >= s.mesh.num_vertices())
        r.fail("seams.stitches", "vertex " + std::to_string(v) + " out of range (" + std::to_string(s.mesh.num_vertices()) + " vertices)");
    if (a == b) r.fail("seams.stitches", "a stitch joins two different vertices");
    s.stitches.push_back({a, b, Eigen::Vector3d::Zero()});
  }
  if (sm.contains("stiffness")) s.stitch_stiffness = r.positive(sm["stiffness"], "seams.stiffness");
  else if (!garment) s.stitch_stiffness = 50.0;
  if (sm.contains("sew_time")) s.sew_time = r.positive(sm["sew_time"], "seams.sew_time");
  if (sm.contains("gravity_delay")) s.gravity_delay = r.nonnegative(sm["gravity_delay"], "seams.gravity_delay");
}

// "damping", "integrator", "dt", "substeps", "frames", "newton".
void read_time_stepping(const Reader& r, const json& j, Scene& s) {
  if (j.contains("damping")) {
    const json& d = j["damping"];
    r.only(d, "damping", {"rayleigh_alpha", "rayleigh_beta", "air"});
    auto nonneg = [&](const char* k, double& out) {
      if (!d.contains(k)) return;
      out = r.number(d[k], std::string("damping.") + k);
      if (out < 0) r.fail(std::string("damping.") + k, "must be >= 0");
    };
    nonneg("rayleigh_alpha", s.rayleigh_alpha);
    nonneg("rayleigh_beta", s.rayleigh_beta);
    nonneg("air", s.air_drag);
  }
  if (j.contains("integrator")) {
    if (!j["integrator"].is_string()) r.fail("integrator", "must be newton, linearized, baraff-witkin or static");
    try {
      s.integrator = parse_integrator(j["integrator"].get<std::string>());
    } catch (const std::exception& e) {
      r.fail("integrator", e.what());
    }
  }
  if (j.contains("dt")) s.dt = r.positive(j["dt"], "dt");
  if (j.contains("substeps")) s.substeps = r.integer(j["substeps"], "substeps", 1);
  if (j.contains("frames")) s.frames = r.integer(j["frames"], "frames", 1);
  if (j.contains("newton")) {
    r.only(j["newton"], "newton", {"tolerance", "tolerance_norm", "max_iterations"});
    if (j["newton"].contains("tolerance_norm")) {
      const auto& n = j["newton"]["tolerance_norm"];
      if (!n.is_string() || (n != "auto" && n != "max" && n != "rms"))
        r.fail("newton.tolerance_norm", "must be \"auto\", \"max\" or \"rms\"");
      s.newton.norm = parse_step_norm(n.get<std::string>());
    }
    if (j["newton"].contains("tolerance")) s.newton.tol_step = r.positive(j["newton"]["tolerance"], "newton.tolerance");
    if (j["newton"].contains("max_iterations"))
      s.newton.max_iterations = r.integer(j["newton"]["max_iterations"], "newton.max_iterations", 1);
  }
}

// "stretch_report": the clamp force of a stretch test, per width.
void read_stretch_report(const Reader& r, const json& j, Scene& s) {
  if (j.contains("stretch_report")) {
    const json& sr = j["stretch_report"];
    r.only(sr, "stretch_report", {"handle", "axis", "length", "width", "middle"});
    for (const char* k : {"handle", "axis", "length", "width", "middle"})
      if (!sr.contains(k)) r.fail(std::string("stretch_report.") + k, "missing");
    s.stretch.enabled = true;
    s.stretch.moving_handle = size_t(r.integer(sr["handle"], "stretch_report.handle", 0));
    if (s.stretch.moving_handle >= s.handles.size())
      r.fail("stretch_report.handle", "no such handle (pins, if given, are handle 0)");
    const Eigen::Vector3d axis = r.vec3(sr["axis"], "stretch_report.axis");
    // A zero (or non-finite) axis has no direction: every force along it would read 0.
    if (!(axis.norm() > 0) || !axis.allFinite()) r.fail("stretch_report.axis", "must be a nonzero, finite direction");
    s.stretch.axis = axis.normalized();
    s.stretch.length = r.positive(sr["length"], "stretch_report.length");
    s.stretch.width = r.positive(sr["width"], "stretch_report.width");
    if (!sr["middle"].is_array() || sr["middle"].size() != 2) r.fail("stretch_report.middle", "must be [u, v]");
    s.stretch.middle = Eigen::Vector2d(r.number(sr["middle"][0], "stretch_report.middle"), r.number(sr["middle"][1], "stretch_report.middle"));
  }
}

}  // namespace

Scene read_scene_json(const std::string& file) {
  const json j = io::read_json_file(file);
  const Reader r{{file}};
  r.only(j, "", {"name", "mesh", "position", "material", "areal_density", "gravity", "pins", "handles", "colliders",
                 "self_collision", "seams", "barrier", "friction", "damping", "integrator", "dt", "substeps", "frames", "newton", "render", "stretch_report"});
  Scene s;
  s.name = std::filesystem::path(file).stem().string();
  if (j.contains("name")) {
    if (!j["name"].is_string()) r.fail("name", "must be a string");
    s.name = j["name"].get<std::string>();
  }
  read_mesh(r, j, s);
  const bool garment = j["mesh"].contains("garment");
  if (j.contains("material")) s.material = r.path(j["material"], "material");
  if (j.contains("areal_density")) s.areal_density = r.positive(j["areal_density"], "areal_density");
  if (j.contains("gravity")) s.gravity = r.vec3(j["gravity"], "gravity");
  read_handles(r, j, s);
  read_contact(r, j, garment, s);
  read_seams(r, j, s);
  read_time_stepping(r, j, s);
  if (j.contains("render")) {
    if (!j["render"].is_array()) r.fail("render", "must be an array of frame numbers");
    for (const json& f : j["render"]) s.render_frames.push_back(r.integer(f, "render", 0));
  }
  read_stretch_report(r, j, s);
  return s;
}

}  // namespace yarnhom::sim
