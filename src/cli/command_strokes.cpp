#include "cli/commands.hpp"
namespace calligraphy::cli {
int command_strokes(const Args&) { return 0; }
}
