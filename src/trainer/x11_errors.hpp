#pragma once
// X11 protocol errors (a window destroyed by another client, e.g. `xdotool windowclose`) would end the
// process through Xlib's default handler, losing the running trial. This handler only records them, and
// the trainer ends the trial safely and saves it.

namespace calligraphy::trainer {

/// Installs the recording handler (XSetErrorHandler); returns false when not running on X11.
bool install_x11_error_handler();
/// True once an X error arrived since the handler was installed.
bool x11_error_seen() noexcept;

}  // namespace calligraphy::trainer
