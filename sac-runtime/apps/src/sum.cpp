// PLACEHOLDER until the app lands (replaced by its implementation).
#include <stdexcept>
#include "sacapps/app.hpp"
namespace sacapps {
std::unique_ptr<App> make_sum() { throw std::logic_error("sum: not implemented yet"); }
}  // namespace sacapps
