// PLACEHOLDER until the app lands (replaced by its implementation).
#include <stdexcept>
#include "sacapps/app.hpp"
namespace sacapps {
std::unique_ptr<App> make_map() { throw std::logic_error("map: not implemented yet"); }
}  // namespace sacapps
