#include "cosserat/io/output_fields.hpp"

namespace cosserat {

// The units are SI, written as in docs/output.md; "1" for a ratio.
NodeField node_field(OutputField field) {
  switch (field) {
    case OutputField::velocity: return {output_field_name(field), "m/s", true};
    case OutputField::area_ratio: return {output_field_name(field), "1", false};
    case OutputField::curvature: return {output_field_name(field), "1/m", false};
    case OutputField::energy_density: return {output_field_name(field), "J/m^2", false};
    case OutputField::broken_springs: return {output_field_name(field), "1", false};
  }
  return {};
}

std::vector<NodeField> node_fields(const std::vector<OutputField>& fields) {
  std::vector<NodeField> described;
  for (const OutputField field : fields) described.push_back(node_field(field));
  return described;
}

OutputFieldValues::OutputFieldValues(const Block& block, const std::vector<OutputField>& fields)
    : fields_(fields) {
  for (const OutputField field : fields)
    if (!node_field(field).vector) scalars_.emplace_back(block);
}

std::vector<NodeFieldValues> OutputFieldValues::evaluate(Simulation& simulation) {
  std::vector<NodeFieldValues> values;
  std::size_t scalar = 0;
  for (const OutputField field : fields_) {
    if (field == OutputField::velocity) {
      values.emplace_back(&simulation.velocities());
    } else {
      Field<double>& buffer = scalars_[scalar++];
      simulation.node_field(field, buffer);
      values.emplace_back(&buffer);
    }
  }
  return values;
}

}  // namespace cosserat
