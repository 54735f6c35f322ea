// Throughput of one Verlet step with solids (docs/contact.md): the flat N x N sheet of bench_step
// resting on what it meets, so that contact works on every step. Four cases:
//   0  no solid (bench_step's step: what a scene without solids runs)
//   1  one plane, the sheet lying on it: every node in contact on every step
//   2  one sphere of radius 5 m touching the middle of the sheet from below: most nodes are
//      tested (within its bounding ball), a few are in contact
//   3  ten solids: the plane, four spheres, two boxes, a cylinder and a capsule just touching
//      the sheet from below, and a box away from it
// The sheet starts 1 mm (the contact offset) above the plane y = 0 that every solid touches
// from below, and moves little in the few hundred steps a benchmark takes.
// Reported as items per second = node-steps per second; run through run_contact.sh.

#include <benchmark/benchmark.h>
#include <mpi.h>
#include <omp.h>

#include "bench_sheet.hpp"
#include "cosserat/time/simulation.hpp"

namespace {

using cosserat::ShapeKind;
using cosserat::SolidSpec;
using cosserat::Vec3;

SolidSpec solid(ShapeKind kind, const Vec3& center) {
  SolidSpec s;
  s.shape.kind = kind;
  s.pose.position = center;
  s.thickness = 1e-3;
  return s;
}

cosserat::Scene sheet(int nodes, int solids) {
  cosserat::Scene s = cosserat::bench::flat_sheet(nodes);
  s.origin = {-5.0, 1e-3, -5.0};
  SolidSpec plane = solid(ShapeKind::plane, {});
  plane.pose.orientation = cosserat::rotation_between({0.0, 0.0, 1.0}, {0.0, 1.0, 0.0});
  if (solids == 1 || solids == 3) s.solids.push_back(plane);
  if (solids == 2) {
    SolidSpec ball = solid(ShapeKind::sphere, {0.0, -5.0, 0.0});
    ball.shape.radius = 5.0;
    s.solids.push_back(ball);
  }
  if (solids == 3) {
    for (const double x : {-3.0, -1.0, 1.0, 3.0}) {
      SolidSpec ball = solid(ShapeKind::sphere, {x, -0.5, 2.0});
      ball.shape.radius = 0.5;
      s.solids.push_back(ball);
    }
    for (const double x : {-2.0, 2.0}) {
      SolidSpec box = solid(ShapeKind::box, {x, -0.2, -2.0});
      box.shape.half_extents = {0.5, 0.2, 0.5};
      s.solids.push_back(box);
    }
    SolidSpec cylinder = solid(ShapeKind::cylinder, {0.0, -0.2, 0.0});
    cylinder.shape.radius = 0.5;
    cylinder.shape.half_length = 0.2;
    cylinder.pose.orientation = plane.pose.orientation;
    s.solids.push_back(cylinder);
    SolidSpec capsule = solid(ShapeKind::capsule, {0.0, -0.01, 4.0});
    capsule.shape.radius = 0.01;
    capsule.shape.half_length = 3.0;
    capsule.pose.orientation = cosserat::rotation_between({0.0, 0.0, 1.0}, {1.0, 0.0, 0.0});
    s.solids.push_back(capsule);
    SolidSpec far = solid(ShapeKind::box, {0.0, 5.0, 0.0});
    far.shape.half_extents = {1.0, 1.0, 1.0};
    s.solids.push_back(far);
  }
  return s;
}

void contact_step(benchmark::State& state) {
  const int nodes = static_cast<int>(state.range(0));
  const int solids = static_cast<int>(state.range(1));
  omp_set_num_threads(static_cast<int>(state.range(2)));
  const cosserat::Scene scene = sheet(nodes, solids);
  cosserat::Simulation sim(scene, MPI_COMM_WORLD);
  for (auto _ : state) {
    if (sim.step()) state.SkipWithError("unstable");
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(nodes) * nodes);
  state.counters["threads"] = static_cast<double>(state.range(2));
  state.counters["solids"] = static_cast<double>(scene.solids.size());
  state.counters["contacts"] = static_cast<double>(sim.contact_summary().max_contacts);
  state.counters["ranks"] = 1;
}

BENCHMARK(contact_step)
    ->ArgNames({"nodes", "case", "threads"})
    ->ArgsProduct({{1024}, {0, 1, 2, 3}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
