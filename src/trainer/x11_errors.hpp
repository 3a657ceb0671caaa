#pragma once
// X11 protocol errors (a window destroyed by another client, e.g. `xdotool windowclose`) would end the
// process through Xlib's default handler, losing the running trial. This handler only records them, and
// the trainer ends the trial safely and saves it.
//
// A lost X connection (the X server gone, the connection killed) is an I/O error: Xlib calls its I/O
// error handler and, should that return, exits the process (status 1, "X connection to :0 broken").
// The trainer's handler never returns: it runs the display-lost ending (set_display_lost_ending: the
// trial stopped with zero force, saved, the session's log closed) on the window thread, without calling
// Xlib, and then ends the process with kDisplayLostStatus.
#include <functional>

namespace calligraphy::trainer {

/// The exit status after a lost display (docs/cli.md, "Exit statuses").
constexpr int kDisplayLostStatus = 4;

/// Installs the recording handler (XSetErrorHandler) and the I/O error handler (XSetIOErrorHandler);
/// returns false when not running on X11.
bool install_x11_error_handler();
/// True once an X error arrived since the handler was installed.
bool x11_error_seen() noexcept;
/// True once the X connection was lost (the I/O error handler ran).
bool display_lost() noexcept;
/// What the I/O error handler runs on the window thread before it ends the process with
/// kDisplayLostStatus: it must not call Xlib (nor GLFW, nor GL); it must return (bounded waits only).
/// An empty function: nothing but the message and the exit.
void set_display_lost_ending(std::function<void()> ending);

}  // namespace calligraphy::trainer
