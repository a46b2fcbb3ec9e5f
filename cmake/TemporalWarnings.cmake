# Settings every target of the project links to, instead of directory-wide flags.
add_library(temporal_warnings INTERFACE)
add_library(temporal::warnings ALIAS temporal_warnings)
target_compile_options(temporal_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow=local -Wno-unused-parameter
  # GCC 12 reports `"text" + std::string(...)` as a memcpy overlap at -O2 (GCC bug 105651, a false positive in
  # libstdc++'s inlined string code); the warning says nothing about this project's code.
  $<$<AND:$<CXX_COMPILER_ID:GNU>,$<VERSION_LESS:$<CXX_COMPILER_VERSION>,13>>:-Wno-restrict>)

# TEMPORAL_WERROR=ON turns the project's warnings into errors (the `ci` and `dev` presets set it, so
# `./setup.sh test`, .ci/run and a development build stop on a warning: a -Wimplicit-fallthrough that GCC reported
# in TEMPORAL_ISA_CALL went unnoticed while warnings only scrolled by). It is part of temporal::warnings, so it
# reaches only the targets that link that (the project's own: stages, tools, tests, benchmarks, the scene
# generator), never the installed package's users.
# Third-party headers come through -isystem or /usr/include, where GCC and clang report nothing, so a Debian
# header cannot fail the build. Off by default: a newer compiler's new warnings should not stop a user's build.
option(TEMPORAL_WERROR "Treat warnings in the project's own code as errors (-Werror)" OFF)
if(TEMPORAL_WERROR)
  target_compile_options(temporal_warnings INTERFACE -Werror)
endif()

# Release code is portable: compiled for x86-64-v2 (SSE4.2, every x86-64 CPU since about 2009), so one build runs
# on every machine of a cluster or a package's users; the hot kernels carry AVX2 and AVX-512 copies chosen at
# run time (temporal/core/isa.h), so speed - part of what the suite reports - does not need -march=native.
# TEMPORAL_NATIVE=ON compiles everything for the build machine instead (local experiments; the binary may not
# run elsewhere). Vectorisation is on, -ffast-math is not (NaN checks must keep working).
add_library(temporal_optimize INTERFACE)
add_library(temporal::optimize ALIAS temporal_optimize)
option(TEMPORAL_NATIVE "Compile for the build machine's CPU (-march=native) instead of portable x86-64-v2" OFF)
if(TEMPORAL_NATIVE)
  target_compile_options(temporal_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-march=native>)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  target_compile_options(temporal_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-march=x86-64-v2>)
endif()
target_compile_options(temporal_optimize INTERFACE $<$<NOT:$<CONFIG:Debug>>:-O3 -fno-math-errno>)

if(TEMPORAL_SANITIZE)
  target_compile_options(temporal_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer)
  target_link_options(temporal_warnings INTERFACE -fsanitize=address,undefined)
endif()
