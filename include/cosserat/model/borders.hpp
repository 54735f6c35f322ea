#pragma once
// Which discretisation of the Cosserat surface a scene uses, and the border rules of the flux
// form (docs/equations.md §2; docs/model.md).

namespace cosserat {

// flux: the equations discretised (docs/equations.md §2.1–2.3); energy: the stored energy
// summed with the trapezoidal rule's weights, each strain where its difference is centred, and
// the force taken as its exact gradient (docs/equations.md, "Energy quadrature"); energy-nodal:
// the stored energy of every strain at its node, with equal weights (the default until
// 2026-12).
enum class Discretisation { flux, energy, energy_nodal };

// As written in scene files and the run summary.
inline const char* discretisation_name(Discretisation d) {
  switch (d) {
    case Discretisation::energy: return "energy";
    case Discretisation::energy_nodal: return "energy-nodal";
    case Discretisation::flux: break;
  }
  return "flux";
}

// Whether the force is the gradient of a stored energy (either energy form).
inline bool is_energy_form(Discretisation d) { return d != Discretisation::flux; }

enum class Borders { symmetric, published };

}  // namespace cosserat
