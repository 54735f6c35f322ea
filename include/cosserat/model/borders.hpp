#pragma once
// Which border rules the flux-form kernel applies (MODEL.md §2.1, §2.3; docs/model.md).

namespace cosserat {

enum class Borders { symmetric, published };

}  // namespace cosserat
