// H.264 video through the ffmpeg tool (temporal/pictures/video.h). Frames go to ffmpeg's stdin over a Unix socket
// pair rather than a pipe so that a write after ffmpeg died returns EPIPE (send with MSG_NOSIGNAL) instead of
// raising SIGPIPE in the calling tool. ffmpeg's messages go to a temporary file read when it fails.
#include "temporal/pictures/video.h"

#include "temporal/io/atomic_file.h"
#include "temporal/core/executable.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace temporal {

std::string find_ffmpeg() { return find_in_path("ffmpeg"); }

struct VideoWriter::Impl {
  std::string path;
  int width = 0, height = 0;
  std::unique_ptr<TemporaryFile> file, log;
  pid_t pid = -1;
  int fd = -1;  // our end of the socket (ffmpeg's stdin)
  std::size_t frames = 0;
  bool finished = false;

  std::string messages() const {
    if (!log) return "no message";
    std::ifstream in(log->path());
    std::stringstream s;
    s << in.rdbuf();
    std::string text = s.str();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    if (text.size() > 600) text = "..." + text.substr(text.size() - 600);
    return text.empty() ? std::string("no message") : text;
  }
  int wait() {
    if (fd >= 0) ::close(fd);
    fd = -1;
    int status = 0;
    if (pid > 0)
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    pid = -1;
    return status;
  }
  ~Impl() {
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      wait();
    }
  }
};

VideoWriter::VideoWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VideoWriter::VideoWriter(VideoWriter&&) noexcept = default;
VideoWriter& VideoWriter::operator=(VideoWriter&&) noexcept = default;
VideoWriter::~VideoWriter() = default;
std::size_t VideoWriter::frames() const { return impl_ ? impl_->frames : 0; }

Expected<VideoWriter> VideoWriter::open(const std::string& path, int width, int height, const VideoOptions& options) {
  if (width < 2 || height < 2 || width % 2 || height % 2)
    return Error::usage("a video needs an even width and height, at least 2 (got " + std::to_string(width) + "x" +
                        std::to_string(height) + ")");
  if (!(options.fps > 0.0) || options.fps > 1000.0) return Error::usage("a video needs a frame rate in (0, 1000]");
  const std::string ffmpeg = options.ffmpeg.empty() ? find_ffmpeg() : options.ffmpeg;
  if (ffmpeg.empty() || ::access(ffmpeg.c_str(), X_OK) != 0)
    return Error::output(path, "cannot write the video: ffmpeg is not installed; install it (apt-get install ffmpeg)");

  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->width = width;
  impl->height = height;
  impl->file = std::make_unique<TemporaryFile>(path);
  impl->log = std::make_unique<TemporaryFile>(path + ".log");
  char fps[32], crf[16];
  std::snprintf(fps, sizeof fps, "%.6g", options.fps);
  std::snprintf(crf, sizeof crf, "%d", options.crf);
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  std::vector<std::string> args = {ffmpeg, "-nostdin", "-hide_banner", "-loglevel", "error", "-y",
                                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size, "-framerate", fps, "-i", "pipe:0",
                                   "-an", "-c:v", "libx264", "-preset", "medium", "-crf", crf, "-pix_fmt", "yuv420p",
                                   // The frames are sRGB-encoded Rec.709 (the report's display encoding): tag the stream
                                   // so players do not guess (BT.709 primaries and matrix, the sRGB transfer curve).
                                   "-color_primaries", "bt709", "-color_trc", "iec61966-2-1", "-colorspace", "bt709",
                                   "-color_range", "tv", "-movflags", "+faststart", "-f", "mp4", impl->file->path()};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);

  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sv) != 0)
    return Error::output(path, "cannot write the video: socketpair() failed");
  const int log_fd = ::open(impl->log->path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(sv[0]);
    ::close(sv[1]);
    if (log_fd >= 0) ::close(log_fd);
    return Error::output(path, "cannot write the video: fork() failed to start ffmpeg");
  }
  if (pid == 0) {
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);  // ffmpeg dies with the tool
    if (::getppid() != parent) ::_exit(127);
    ::dup2(sv[1], 0);
    const int null = ::open("/dev/null", O_WRONLY);
    if (null >= 0) ::dup2(null, 1);
    if (log_fd >= 0) ::dup2(log_fd, 2);
    ::execv(ffmpeg.c_str(), argv.data());
    ::_exit(127);
  }
  ::close(sv[1]);
  if (log_fd >= 0) ::close(log_fd);
  ::shutdown(sv[0], SHUT_RD);
  impl->pid = pid;
  impl->fd = sv[0];
  return VideoWriter(std::move(impl));
}

Status VideoWriter::add(const Picture& frame) {
  Impl& v = *impl_;
  if (v.finished || v.fd < 0) return Error::internal("VideoWriter::add after finish");
  if (frame.width() != v.width || frame.height() != v.height)
    return Error::internal("VideoWriter::add: frame size differs from the video's");
  const std::uint8_t* data = frame.bytes();
  std::size_t left = std::size_t(v.width) * std::size_t(v.height) * 3;
  while (left > 0) {
    const ssize_t sent = ::send(v.fd, data, left, MSG_NOSIGNAL);
    if (sent < 0 && errno == EINTR) continue;
    if (sent <= 0) {
      v.wait();
      return Error::output(v.path, "ffmpeg stopped while encoding the video: " + v.messages());
    }
    data += sent;
    left -= std::size_t(sent);
  }
  ++v.frames;
  return {};
}

Status VideoWriter::finish() {
  Impl& v = *impl_;
  if (v.finished) return {};
  v.finished = true;
  const int status = v.wait();
  const std::string messages = v.messages();
  v.log.reset();  // ffmpeg's messages are not an output
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    return Error::output(v.path, "ffmpeg could not encode the video (exit " +
                                     std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + "): " + messages);
  if (v.frames == 0) return Error::output(v.path, "no frame was given to the video");
  return v.file->commit();
}

}  // namespace temporal
