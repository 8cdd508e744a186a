// PLACEHOLDER until the app lands (replaced by its implementation).
#include <stdexcept>
#include "sacapps/app.hpp"
namespace sacapps {
std::unique_ptr<App> make_exptrees() { throw std::logic_error("exptrees: not implemented yet"); }
}  // namespace sacapps
