#include "temporal/gpu/timer.h"

namespace temporal::gpu {

const char* clock_name(Clock clock) {
  return clock == Clock::GpuQuery ? "gpu (GL_TIME_ELAPSED)" : "wall clock after glFinish";
}

Timer::Timer(std::shared_ptr<Context> context) : context_(std::move(context)) {
  if (context_->timer_queries() && context_->make_current()) context_->gl().GenQueries(1, &query_);
}

Timer::~Timer() {
  if (query_ && context_->make_current()) context_->gl().DeleteQueries(1, &query_);
}

Clock Timer::clock() const { return query_ ? Clock::GpuQuery : Clock::WallAfterFinish; }

void Timer::start() {
  if (!context_->make_current()) return;
  if (query_) {
    context_->gl().BeginQuery(GL_TIME_ELAPSED, query_);
  } else {
    context_->finish();
    begin_ = std::chrono::steady_clock::now();
  }
}

double Timer::stop_ms() {
  if (!context_->make_current()) return 0.0;
  const GlFunctions& gl = context_->gl();
  if (query_) {
    gl.EndQuery(GL_TIME_ELAPSED);
    GLuint64 ns = 0;
    gl.GetQueryObjectui64v(query_, GL_QUERY_RESULT, &ns);
    return double(ns) * 1e-6;
  }
  context_->finish();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin_).count();
}

}  // namespace temporal::gpu
