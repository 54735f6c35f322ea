#pragma once
// Which discretisation of the Cosserat surface a scene uses, and the border rules of the flux
// form (MODEL.md §2.1–2.5; docs/model.md).

namespace cosserat {

// flux: the equations discretised (§2.1–2.3); energy: the stored energy discretised and the
// force taken as its exact gradient (§2.5).
enum class Discretisation { flux, energy };

enum class Borders { symmetric, published };

}  // namespace cosserat
