# Every third-party package comes from Debian 12 (installed by ./setup.sh). Traps found on this platform
# are recorded in docs/building.md.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

find_package(OpenImageIO CONFIG REQUIRED)
# Debian's OpenImageIO config names /usr/include/opencv4, which is absent unless OpenCV is installed.
get_target_property(_oiio_inc OpenImageIO::OpenImageIO INTERFACE_INCLUDE_DIRECTORIES)
list(FILTER _oiio_inc EXCLUDE REGEX "opencv4")
set_target_properties(OpenImageIO::OpenImageIO PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_oiio_inc}")
find_package(OpenEXR CONFIG REQUIRED)

# OpenColorIO 2.1's CMake config is not installed by Debian; pkg-config works.
pkg_check_modules(OCIO REQUIRED IMPORTED_TARGET OpenColorIO>=2.1)

find_package(glm CONFIG REQUIRED)
find_package(TBB CONFIG REQUIRED)
find_package(nlohmann_json CONFIG REQUIRED)
find_package(CLI11 CONFIG REQUIRED)

# The renderer (OSMesa) and the plots (VTK, which links libGL) live in separate targets: both libraries
# export every gl* symbol, and an executable that loads libGL first silently breaks OSMesa.
pkg_check_modules(OSMESA REQUIRED IMPORTED_TARGET osmesa)
# EGL's device platform (the renderer's second context and the compute kernels' context, one module:
# temporal/gpu/egl.h) through glvnd's libEGL (libegl-dev; Mesa's software device comes from libegl-mesa0, a GPU's
# from its driver). Nothing links it: the gpu stage opens libEGL.so.1 at run time and needs only its headers; GL
# entry points come from eglGetProcAddress.
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
find_package(TinyGLTF CONFIG REQUIRED)
# stb_image (libstb, the library tinygltf decodes glTF images with) decodes USD textures too.
pkg_check_modules(STB REQUIRED IMPORTED_TARGET stb)

find_package(MPI REQUIRED COMPONENTS C)
set(TEMPORAL_VTK_COMPONENTS CommonCore CommonDataModel ChartsCore ViewsContext2D RenderingContext2D
  RenderingContextOpenGL2 RenderingCore RenderingOpenGL2 RenderingFreeType IOImage InteractionStyle
  IOExportGL2PS RenderingGL2PSOpenGL2)
find_package(VTK 9.1 REQUIRED COMPONENTS ${TEMPORAL_VTK_COMPONENTS})
list(JOIN TEMPORAL_VTK_COMPONENTS " " TEMPORAL_VTK_COMPONENTS)  # for temporalConfig.cmake
# PDF charts: the chart's SVG (VTK through GL2PS) drawn by librsvg onto a cairo PDF surface, which embeds the fonts
# as subsets. VTK's own PDF exporter (libharu) drew every marker as a disc filling the plot area and left its
# Helvetica unembedded (issue 25).
pkg_check_modules(RSVG REQUIRED IMPORTED_TARGET librsvg-2.0 cairo-pdf)

if(TEMPORAL_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
endif()
if(TEMPORAL_BUILD_BENCHMARKS)
  find_package(benchmark CONFIG REQUIRED)
endif()
