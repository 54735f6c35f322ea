#include "cosserat/io/summary.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cosserat/grid/reduce.hpp"

namespace cosserat {
namespace {

std::string json_string(const std::string& text) {
  std::string quoted = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': quoted += "\\\""; break;
      case '\\': quoted += "\\\\"; break;
      case '\n': quoted += "\\n"; break;
      case '\r': quoted += "\\r"; break;
      case '\t': quoted += "\\t"; break;
      case '\b': quoted += "\\b"; break;
      case '\f': quoted += "\\f"; break;
      default:
        // Other control characters have no short escape; bytes from 0x80 up are UTF-8 and JSON
        // takes them as they are.
        if (static_cast<unsigned char>(c) < 0x20) {
          quoted += fmt::format("\\u{:04x}", static_cast<unsigned char>(c));
        } else {
          quoted += c;
        }
    }
  }
  return quoted + '"';
}

// fmt's default is the shortest text that reads back as the same double, so every bit of the
// value survives without the noise digits of a fixed %.17g ("0.001", not
// "0.0010000000000000000208"). JSON has no NaN or infinity.
std::string json_number(double value) {
  return std::isfinite(value) ? fmt::format("{}", value) : "null";
}

}  // namespace

RunSummary summarize_run(const Scene& scene, Simulation& simulation, const StepLoopResult& loop,
                         const RunPlacement& placement, MPI_Comm comm) {
  const Diagnostics diagnostics = simulation.diagnostics();
  const double steps_run = static_cast<double>(simulation.step_index() - loop.first_step);
  const double wall = loop.wall_seconds;
  RunSummary summary;
  summary.scene = scene.title.empty() ? scene.name : scene.title;
  summary.m = scene.m;
  summary.n = scene.n;
  summary.ranks = placement.ranks;
  summary.threads = placement.threads;
  summary.thread_steps = loop.thread_steps;
  summary.parts_k = placement.parts_k;
  summary.parts_l = placement.parts_l;
  summary.integrator = integrator_name(scene.integrator);
  summary.dt = scene.adaptive ? std::nan("") : scene.dt;
  summary.steps = simulation.step_index();
  summary.sim_time = simulation.time();
  summary.wall_seconds = wall;
  summary.node_steps_per_second =
      wall > 0.0 ? static_cast<double>(scene.m) * scene.n * steps_run / wall : 0.0;
  summary.halo_seconds = global_max(loop.halo_seconds, comm);
  summary.restarted_from = placement.restarted_from;
  summary.status = loop.failure ? "unstable" : "ok";
  if (loop.failure) summary.unstable_step = loop.failure->step;
  summary.area_ratio = diagnostics.area_ratio;
  summary.max_speed = diagnostics.max_speed;
  summary.discretisation = scene.model_kind == ModelKind::mass_spring
                               ? model_kind_name(scene.model_kind)
                               : discretisation_name(scene.discretisation);
  summary.kinetic_energy = diagnostics.kinetic_energy;
  summary.elastic_energy = simulation.elastic_energy();
  summary.gravitational_energy = diagnostics.gravitational_energy;
  summary.center_of_mass = diagnostics.center_of_mass;
  summary.output = placement.output;
  summary.linear_solves = simulation.stepper().linear_solves();
  summary.rest = loop.rest;
  summary.adaptive = loop.adaptive;
  if (const Contact* contact = simulation.contact()) {
    summary.contact = simulation.contact_summary();
    for (std::size_t i = 0; i < contact->size(); ++i)
      summary.solids.push_back({contact->spec(i).name,
                                std::string(solid_motion_name(contact->spec(i).motion)),
                                contact->state(i)});
  }
  summary.self_contact = simulation.self_contact_summary();
  return summary;
}

std::string to_json(const RunSummary& s) {
  const std::string unstable_step =
      s.unstable_step ? fmt::format("{}", *s.unstable_step) : "null";
  const std::string restarted_from =
      s.restarted_from ? fmt::format("{}", *s.restarted_from) : "null";
  const Vec3& com = s.center_of_mass;
  std::string linear_solves = "null";
  if (const auto& l = s.linear_solves) {
    linear_solves = fmt::format(
        R"({{"solves": {}, "iterations": {}, "mean_iterations": {}, "most_iterations": {}, )"
        R"("jacobian_seconds": {}, "jacobians": {}, "solve_seconds": {}, "setup_seconds": {}}})",
        l->solves, l->iterations,
        json_number(l->solves > 0 ? static_cast<double>(l->iterations) / l->solves : 0.0),
        l->most_iterations, json_number(l->jacobian_seconds), l->jacobians,
        json_number(l->solve_seconds), json_number(l->setup_seconds));
  }
  std::string rest = "null";
  if (const auto& r = s.rest) {
    rest = fmt::format(R"({{"fraction": {}, "peak_kinetic_energy": {}, "step": {}}})",
                       json_number(r->fraction), json_number(r->peak_kinetic_energy),
                       r->step ? fmt::format("{}", *r->step) : "null");
  }
  std::string adaptive = "null";
  if (const auto& a = s.adaptive) {
    adaptive = fmt::format(R"({{"smallest_dt": {}, "largest_dt": {}, "rollbacks": {}}})",
                           json_number(a->smallest_dt), json_number(a->largest_dt),
                           a->rollbacks);
  }
  const auto vector = [](const Vec3& v) {
    return fmt::format("[{}, {}, {}]", json_number(v.x), json_number(v.y), json_number(v.z));
  };
  std::string solids = "[]";
  if (!s.solids.empty()) {
    solids = "[";
    for (std::size_t i = 0; i < s.solids.size(); ++i) {
      const SolidState& st = s.solids[i].state;
      const Quaternion& q = st.pose.orientation;
      solids += fmt::format(
          R"({}{{"name": {}, "motion": {}, "position": {}, "orientation": [{}, {}, {}, {}], )"
          R"("velocity": {}, "angular_velocity": {}}})",
          i == 0 ? "\n    " : ",\n    ", json_string(s.solids[i].name),
          json_string(s.solids[i].motion), vector(st.pose.position), json_number(q.w),
          json_number(q.x), json_number(q.y), json_number(q.z), vector(st.velocity),
          vector(st.angular_velocity));
    }
    solids += "\n  ]";
  }
  const std::string max_penetration =
      s.contact ? json_number(s.contact->max_penetration) : "null";
  const std::string max_contacts =
      s.contact ? fmt::format("{}", s.contact->max_contacts) : "null";
  const std::string self_contact =
      s.self_contact ? fmt::format(R"({{"thickness": {}, "max_pairs": {}, "closest": {}}})",
                                   json_number(s.self_contact->thickness),
                                   s.self_contact->max_pairs,
                                   std::isfinite(s.self_contact->closest)
                                       ? json_number(s.self_contact->closest)
                                       : std::string("null"))
                     : "null";
  return fmt::format(
      R"({{
  "scene": {},
  "grid": [{}, {}],
  "ranks": {},
  "threads": {},
  "thread_steps": [{}],
  "split": [{}, {}],
  "integrator": {},
  "discretisation": {},
  "dt": {},
  "steps": {},
  "sim_time": {},
  "wall_seconds": {},
  "node_steps_per_second": {},
  "halo_seconds": {},
  "restarted_from": {},
  "status": {},
  "unstable_step": {},
  "area_ratio": {},
  "max_speed": {},
  "kinetic_energy": {},
  "elastic_energy": {},
  "gravitational_energy": {},
  "center_of_mass": [{}, {}, {}],
  "output": {},
  "linear_solves": {},
  "rest": {},
  "adaptive": {},
  "max_penetration": {},
  "max_contacts": {},
  "solids": {},
  "self_contact": {}
}}
)",
      json_string(s.scene), s.m, s.n, s.ranks, s.threads, fmt::join(s.thread_steps, ", "),
      s.parts_k, s.parts_l,
      json_string(s.integrator), json_string(s.discretisation), json_number(s.dt), s.steps, json_number(s.sim_time),
      json_number(s.wall_seconds), json_number(s.node_steps_per_second),
      json_number(s.halo_seconds), restarted_from, json_string(s.status), unstable_step,
      json_number(s.area_ratio), json_number(s.max_speed), json_number(s.kinetic_energy),
      json_number(s.elastic_energy), json_number(s.gravitational_energy), json_number(com.x), json_number(com.y), json_number(com.z), json_string(s.output), linear_solves, rest, adaptive,
      max_penetration, max_contacts, solids, self_contact);
}

void write_summary(const std::string& path, const RunSummary& summary) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << to_json(summary);
  out.close();
  if (!out) throw std::runtime_error(fmt::format("summary file '{}': write failed", path));
}

}  // namespace cosserat
