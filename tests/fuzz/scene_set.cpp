// libFuzzer target: --set arguments, one per input line, applied to a valid scene that has
// every section, so each override reaches a reader. A SceneError is the expected refusal;
// anything else escaping, a crash, a sanitizer report or a hang is a finding. Inputs that
// only ask for more memory than a machine has are skipped (affordable.hpp).

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "affordable.hpp"
#include "cosserat/scene/scene.hpp"

namespace {

constexpr std::string_view kScene = R"(title = "fuzz base"

[grid]
nodes = [12, 10]
size = [2.0, 1.5]
origin = [0.0, 0.0, 1.0]
u = [1.0, 0.0, 0.0]
v = [0.0, 0.0, -1.0]

[material]
preset = "cotton-10m"
phi = [0.01, 0.0, 0.01]

[model]
kind = "cosserat"
discretisation = "flux"
borders = "symmetric"

[environment]
gravity = [0.0, 0.0, -9.81]
damping = 0.1
initial_velocity = [0.0, 0.1, 0.0]
fluid = { viscosity = 0.5, velocity = [1.0, 0.0, 0.0] }

[time]
integrator = "verlet"
dt = 1e-4
steps = 100
output_every = 10

[time.solver]
ksp = "gmres"
rtol = 1e-8

[[fix]]
nodes = [[0, 0], [11, 0]]
axes = "xz"

[[fix]]
region = { row = 9 }
start = 0
end = 50

[[load]]
region = { disk = { center = [5.5, 4.5], radius = 2.0 } }
force = [0.0, 1.0, 0.0]

[[load]]
region = { rect = [0, 0, 3, 3] }
force = [0.0, 0.0, -1.0]
start = 10
)";

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  std::size_t begin = 0;
  while (begin <= input.size()) {
    const std::size_t end = std::min(input.find('\n', begin), input.size());
    overrides.emplace_back(input.substr(begin, end - begin));
    begin = end + 1;
  }
  const std::string scene(kScene);
  if (!cosserat::fuzz::affordable(scene, overrides)) return 0;
  try {
    cosserat::parse_scene(scene, "fuzz.toml", overrides);
  } catch (const cosserat::SceneError&) {
  }
  return 0;
}
