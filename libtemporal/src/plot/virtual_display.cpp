// An X display for VTK (temporal/plot/plot.h): Debian's VTK 9.1 is built for X11 only and aborts without a display.
#include "temporal/plot/plot.h"

#include "temporal/core/executable.h"

#include <X11/Xlib.h>
#undef Status  // Xlib defines Status as a macro; temporal::Status must stay usable
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <string>
#include <vector>

namespace temporal {
namespace {

bool display_answers(const char* name) {
  if (!name || !*name) return false;
  Display* d = XOpenDisplay(name);
  if (!d) return false;
  XCloseDisplay(d);
  return true;
}

}  // namespace

Expected<VirtualDisplay> VirtualDisplay::ensure() {
  VirtualDisplay vd;
  const char* current = std::getenv("DISPLAY");
  vd.had_previous_ = current != nullptr;
  if (current) vd.previous_display_ = current;
  if (display_answers(current)) {
    vd.display_ = current;
    return vd;
  }
  const std::string xvfb = find_in_path("Xvfb");
  const std::string why = current && *current ? "no X server answers on DISPLAY=" + std::string(current)
                                              : std::string("DISPLAY is unset");
  if (xvfb.empty())
    return Error::output({}, "cannot draw the plots: " + why +
                                 " and Xvfb is not installed; install it (apt-get install xvfb), run under an X "
                                 "server, or leave out --plot");

  int fds[2];
  if (::pipe(fds) != 0) return Error::output({}, "cannot draw the plots: pipe() failed for Xvfb");
  // Everything the child needs is prepared before fork: after it only async-signal-safe calls are allowed.
  const std::string fd_text = std::to_string(fds[1]);
  std::vector<std::string> args = {"Xvfb", "-displayfd", fd_text, "-nolisten", "tcp", "-screen", "0", "1920x1080x24"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t parent = ::getpid();

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    return Error::output({}, "cannot draw the plots: fork() failed to start Xvfb");
  }
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // the server dies with compare, even if compare is killed
    if (::getppid() != parent) ::_exit(127);
    ::close(fds[0]);
    const int null = ::open("/dev/null", O_RDWR);
    if (null >= 0) {
      ::dup2(null, 0);
      ::dup2(null, 1);
      ::dup2(null, 2);
    }
    ::execv(xvfb.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  vd.pid_ = pid;

  // Xvfb writes the display number it took, then a newline, once it accepts connections.
  std::string number;
  bool done = false;
  while (!done) {
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, 15000);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) break;
    char c = 0;
    const ssize_t got = ::read(fds[0], &c, 1);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    if (c == '\n') done = true;
    else number += c;
  }
  ::close(fds[0]);
  if (!done || number.empty()) {
    vd.stop();
    return Error::output({}, "cannot draw the plots: " + why + " and " + xvfb +
                                 " did not start (try running `Xvfb -displayfd 1` to see why), or leave out --plot");
  }
  vd.display_ = ":" + number;
  ::setenv("DISPLAY", vd.display_.c_str(), 1);
  return vd;
}

VirtualDisplay::VirtualDisplay(VirtualDisplay&& other) noexcept
    : pid_(other.pid_),
      display_(std::move(other.display_)),
      previous_display_(std::move(other.previous_display_)),
      had_previous_(other.had_previous_) {
  other.pid_ = -1;
}

VirtualDisplay& VirtualDisplay::operator=(VirtualDisplay&& other) noexcept {
  if (this != &other) {
    stop();
    pid_ = other.pid_;
    display_ = std::move(other.display_);
    previous_display_ = std::move(other.previous_display_);
    had_previous_ = other.had_previous_;
    other.pid_ = -1;
  }
  return *this;
}

VirtualDisplay::~VirtualDisplay() { stop(); }

void VirtualDisplay::stop() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGTERM);
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
  if (had_previous_) ::setenv("DISPLAY", previous_display_.c_str(), 1);
  else ::unsetenv("DISPLAY");
}

}  // namespace temporal
