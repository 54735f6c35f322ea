#pragma once
// Which discretisation of the Cosserat surface a scene uses, and the border rules of the flux
// form (MODEL.md §2.1–2.5; docs/model.md).

namespace cosserat {

// flux: the equations discretised (§2.1–2.3); energy: the stored energy discretised and the
// force taken as its exact gradient (§2.5).
enum class Discretisation { flux, energy };

// As written in scene files and the run summary.
inline const char* discretisation_name(Discretisation d) {
  return d == Discretisation::energy ? "energy" : "flux";
}

enum class Borders { symmetric, published };

}  // namespace cosserat
