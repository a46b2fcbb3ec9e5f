# Helpers that give every libtemporal stage the same shape: one static library per stage folder, an alias
# `temporal::<stage>`, public headers in libtemporal/include/temporal/<stage>/, install and export rules
# grouped into the package components of temporalConfig.cmake (core, methods, scene, render, plot).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(TEMPORAL_INCLUDE_ROOT ${PROJECT_SOURCE_DIR}/libtemporal/include)
set(TEMPORAL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/temporal)

# The stages each stage may include and link (the layering rule; cmake/CheckLayering.cmake reads it).
set(TEMPORAL_STAGE_DEPS_core "")
set(TEMPORAL_STAGE_DEPS_io "core")
set(TEMPORAL_STAGE_DEPS_metrics "core")
set(TEMPORAL_STAGE_DEPS_compare "core;io;metrics")
set(TEMPORAL_STAGE_DEPS_gpu "core")
set(TEMPORAL_STAGE_DEPS_upsample "core;gpu")
set(TEMPORAL_STAGE_DEPS_phlm "core;gpu")
set(TEMPORAL_STAGE_DEPS_morph "core;gpu")
set(TEMPORAL_STAGE_DEPS_scene "core")
set(TEMPORAL_STAGE_DEPS_render "core;scene;gpu")
set(TEMPORAL_STAGE_DEPS_replay "core;io;scene;render")
set(TEMPORAL_STAGE_DEPS_plot "core;io;metrics;compare")
set(TEMPORAL_STAGE_DEPS_pictures "core;io;metrics;compare")
set(TEMPORAL_STAGE_DEPS_report "core;io;metrics;compare;pictures;plot")
set(TEMPORAL_STAGES core io metrics compare gpu upsample phlm morph scene render replay plot pictures report)
# Package component of each stage.
set(TEMPORAL_COMPONENT_core core)
set(TEMPORAL_COMPONENT_io core)
set(TEMPORAL_COMPONENT_metrics core)
set(TEMPORAL_COMPONENT_compare core)
set(TEMPORAL_COMPONENT_gpu methods)
set(TEMPORAL_COMPONENT_upsample methods)
set(TEMPORAL_COMPONENT_phlm methods)
set(TEMPORAL_COMPONENT_morph methods)
set(TEMPORAL_COMPONENT_scene scene)
set(TEMPORAL_COMPONENT_render render)
set(TEMPORAL_COMPONENT_replay render)
set(TEMPORAL_COMPONENT_plot plot)
set(TEMPORAL_COMPONENT_pictures core)
set(TEMPORAL_COMPONENT_report plot)

# temporal_add_stage(STAGE SOURCES ... [PUBLIC libs...] [PRIVATE libs...]): the static library of a stage.
# It links the stages named in TEMPORAL_STAGE_DEPS_<STAGE> publicly (nothing else from the project).
function(temporal_add_stage stage)
  cmake_parse_arguments(arg "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  set(target temporal_${stage})
  add_library(${target} STATIC ${arg_SOURCES})
  add_library(temporal::${stage} ALIAS ${target})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${stage} POSITION_INDEPENDENT_CODE ON)
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${TEMPORAL_INCLUDE_ROOT}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  # The stage's own folder, for the kernel files temporal/core/isa_copies.inc includes by name (a quoted include
  # in that file searches its own folder first, not the stage's).
  target_include_directories(${target} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  foreach(dep IN LISTS TEMPORAL_STAGE_DEPS_${stage})
    target_link_libraries(${target} PUBLIC temporal::${dep})
  endforeach()
  target_link_libraries(${target} PUBLIC ${arg_PUBLIC} PRIVATE ${arg_PRIVATE}
    $<BUILD_INTERFACE:temporal::warnings> $<BUILD_INTERFACE:temporal::optimize>)
  temporal_install_targets(${TEMPORAL_COMPONENT_${stage}} ${target})
  install(DIRECTORY ${TEMPORAL_INCLUDE_ROOT}/temporal/${stage} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/temporal
    COMPONENT ${TEMPORAL_COMPONENT_${stage}} FILES_MATCHING PATTERN "*.h")
endfunction()

# Installs targets into the export set of a package component.
function(temporal_install_targets component)
  install(TARGETS ${ARGN} EXPORT temporal-${component}-targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT ${component}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT ${component}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()

# The layering check: runs before any stage compiles, and again whenever a library source or header changes.
function(temporal_layering_check)
  file(GLOB_RECURSE _sources CONFIGURE_DEPENDS
    ${PROJECT_SOURCE_DIR}/libtemporal/src/*.cpp ${PROJECT_SOURCE_DIR}/libtemporal/src/*.h
    ${TEMPORAL_INCLUDE_ROOT}/temporal/*.h)
  set(_args "")
  foreach(stage IN LISTS TEMPORAL_STAGES)
    list(JOIN TEMPORAL_STAGE_DEPS_${stage} "," _deps)
    list(APPEND _args "-DDEPS_${stage}=${_deps}")
  endforeach()
  list(JOIN TEMPORAL_STAGES "," _stages)
  add_custom_command(OUTPUT ${CMAKE_CURRENT_BINARY_DIR}/layering.stamp
    COMMAND ${CMAKE_COMMAND} -DROOT=${PROJECT_SOURCE_DIR}/libtemporal -DSTAGES=${_stages} ${_args}
            -P ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
    COMMAND ${CMAKE_COMMAND} -E touch ${CMAKE_CURRENT_BINARY_DIR}/layering.stamp
    DEPENDS ${_sources} ${PROJECT_SOURCE_DIR}/cmake/CheckLayering.cmake
    COMMENT "Checking that each libtemporal stage includes only the stages it links")
  add_custom_target(temporal_layering DEPENDS ${CMAKE_CURRENT_BINARY_DIR}/layering.stamp)
  foreach(stage IN LISTS TEMPORAL_STAGES)
    add_dependencies(temporal_${stage} temporal_layering)
  endforeach()
endfunction()

# temporalConfig.cmake, its version file and one targets file per component.
function(temporal_install_package)
  foreach(component core methods scene render plot)
    install(EXPORT temporal-${component}-targets NAMESPACE temporal:: DESTINATION ${TEMPORAL_INSTALL_CMAKEDIR}
      FILE temporal-${component}-targets.cmake COMPONENT ${component})
  endforeach()
  configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/temporalConfig.cmake.in
    ${CMAKE_CURRENT_BINARY_DIR}/temporalConfig.cmake INSTALL_DESTINATION ${TEMPORAL_INSTALL_CMAKEDIR})
  write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/temporalConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${CMAKE_CURRENT_BINARY_DIR}/temporalConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/temporalConfigVersion.cmake
    DESTINATION ${TEMPORAL_INSTALL_CMAKEDIR} COMPONENT core)
endfunction()
