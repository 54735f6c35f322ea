#pragma once
// The per-node fields of a scene's [output] (docs/output.md, "Fields") as the output writes
// them: their names and units, and their values at a simulation's current state, computed into
// buffers kept from one frame to the next.

#include <vector>

#include "cosserat/grid/block.hpp"
#include "cosserat/io/frame_writer.hpp"
#include "cosserat/scene/scene.hpp"
#include "cosserat/time/simulation.hpp"

namespace cosserat {

// The dataset /fields/<name> of one field: its name, units and shape.
NodeField node_field(OutputField field);
std::vector<NodeField> node_fields(const std::vector<OutputField>& fields);

class OutputFieldValues {
 public:
  // Buffers for the scalar ones of `fields` on the block.
  OutputFieldValues(const Block& block, const std::vector<OutputField>& fields);

  // Each field at the simulation's current state, in the order given, for
  // FrameWriter::write_frame; valid until the next call or until the simulation steps. Reads
  // the positions' ghosts, which every step leaves current.
  std::vector<NodeFieldValues> evaluate(Simulation& simulation);

 private:
  std::vector<OutputField> fields_;
  std::vector<Field<double>> scalars_;  // one per scalar field, in order
};

}  // namespace cosserat
