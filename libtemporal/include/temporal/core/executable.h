// Finding an external program: compare starts Xvfb for its charts and ffmpeg for its videos.
#pragma once

#include <string>

namespace temporal {

// The first regular, executable file `program` in the folders of $PATH (an empty entry is the current folder;
// without $PATH, /usr/local/bin:/usr/bin:/bin); empty when there is none.
std::string find_in_path(const std::string& program);

}  // namespace temporal
