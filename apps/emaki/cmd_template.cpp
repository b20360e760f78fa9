#include "apps/emaki/commands.h"
namespace emaki::app {
int run_template(const Args&) { return 0; }
}
