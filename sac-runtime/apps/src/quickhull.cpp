// PLACEHOLDER until the app lands (replaced by its implementation).
#include <stdexcept>
#include "sacapps/app.hpp"
namespace sacapps {
std::unique_ptr<App> make_quickhull() { throw std::logic_error("quickhull: not implemented yet"); }
}  // namespace sacapps
