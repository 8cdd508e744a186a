#include <sac/sac.hpp>

int main() {
  sac::Engine e;
  (void)e;
  return 0;
}
