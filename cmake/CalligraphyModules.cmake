# calligraphy_module(NAME PACKAGE haptics|research|own|none [DEPENDS module...] [SOURCE_DIR dir] [SOURCES extra...])
#
# Declares the static library calligraphy_NAME from src/<SOURCE_DIR or NAME>/*.cpp. Its public headers
# are include/calligraphy/NAME/; the target sees them through a folder of its own in the build tree
# (module-include/NAME/calligraphy/NAME -> include/calligraphy/NAME), and a module sees another's
# public headers only by linking it. So a file that includes a module above its own does not compile.
# Private headers stay under src/ (PRIVATE include path); scripts/check-layering.py checks their
# include lines too. PACKAGE names the installed package the module belongs to (docs/architecture.md,
# "Packages"): `haptics` (what a haptic application needs), `research` (simulated writers, studies,
# reports), `own` (a component of its own, installed only when asked for by name: the USB transports, the
# emulator), or `none` (not installed).
set(CALLIGRAPHY_HAPTICS_MODULES "" CACHE INTERNAL "")
set(CALLIGRAPHY_RESEARCH_MODULES "" CACHE INTERNAL "")

# calligraphy_precompile(TARGET [header...]): precompiles Eigen, the standard headers most files include
# and the given third-party headers for TARGET. CLI11, Catch2, pybind11 and nlohmann-json are header-only
# and were parsed again by every file of the CLI, the tests and the Python module (docs/testing.md). Not
# used for the library's modules: there GCC 12 at -O3 with a precompiled header gave a false
# -Warray-bounds inside std::string (src/devices/phantom/phantom_backends.cpp), and their files include
# little beyond Eigen.
function(calligraphy_precompile target)
  target_precompile_headers(${target} PRIVATE <Eigen/Core> <algorithm> <cmath> <string> <vector> ${ARGN})
endfunction()

# calligraphy_private_link(TARGET dependency... [INSTALLED library...]): links TARGET to the dependencies
# (imported targets or library paths) in this build only, and names the INSTALLED plain libraries in the
# exported package instead. The modules are static archives, so a consumer still links what they call
# (-lspdlog, -lz, ...), but needs no find_package of our private dependencies: the installed
# calligraphyConfig.cmake finds Eigen3 alone, and holds no path of the machine that built it.
# A header-only dependency (nlohmann_json) has no INSTALLED library.
function(calligraphy_private_link target)
  cmake_parse_arguments(link "" "" "INSTALLED" ${ARGN})
  foreach(dependency IN LISTS link_UNPARSED_ARGUMENTS)
    target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:${dependency}>)
  endforeach()
  foreach(library IN LISTS link_INSTALLED)
    target_link_libraries(${target} PRIVATE $<INSTALL_INTERFACE:${library}>)
  endforeach()
endfunction()

# calligraphy_installed_definitions(TARGET dependency...): the compile definitions the dependencies' imported
# targets (and the targets they link) ask of their users, given to TARGET's users in the installed package
# only: a private dependency whose headers a consumer includes too must be compiled the same way there.
function(calligraphy_installed_definitions target)
  set(definitions "")
  set(pending ${ARGN})
  set(seen "")
  while(pending)
    list(POP_FRONT pending dependency)
    if(NOT TARGET ${dependency} OR dependency IN_LIST seen)
      continue()
    endif()
    list(APPEND seen ${dependency})
    get_target_property(own ${dependency} INTERFACE_COMPILE_DEFINITIONS)
    if(own)
      list(APPEND definitions ${own})
    endif()
    get_target_property(links ${dependency} INTERFACE_LINK_LIBRARIES)
    if(links)
      list(APPEND pending ${links})
    endif()
  endwhile()
  list(REMOVE_DUPLICATES definitions)
  foreach(definition IN LISTS definitions)
    target_compile_definitions(${target} INTERFACE $<INSTALL_INTERFACE:${definition}>)
  endforeach()
endfunction()

function(calligraphy_module name)
  cmake_parse_arguments(module "" "SOURCE_DIR;PACKAGE" "DEPENDS;SOURCES" ${ARGN})
  if(NOT module_PACKAGE MATCHES "^(haptics|research|own|none)$")
    message(FATAL_ERROR "calligraphy_module(${name}): PACKAGE must be haptics, research, own or none")
  endif()
  if(NOT module_SOURCE_DIR)
    set(module_SOURCE_DIR ${name})
  endif()
  file(GLOB sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${module_SOURCE_DIR}/*.cpp)
  set(target calligraphy_${name})
  add_library(${target} STATIC ${sources} ${module_SOURCES})
  set(staged ${PROJECT_BINARY_DIR}/module-include/${name})
  if(EXISTS ${PROJECT_SOURCE_DIR}/include/calligraphy/${name})
    file(MAKE_DIRECTORY ${staged}/calligraphy)
    if(NOT EXISTS ${staged}/calligraphy/${name})
      file(CREATE_LINK ${PROJECT_SOURCE_DIR}/include/calligraphy/${name} ${staged}/calligraphy/${name} SYMBOLIC)
    endif()
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${staged}>)
  endif()
  target_include_directories(${target}
    PUBLIC $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${PROJECT_SOURCE_DIR}/src)
  foreach(dependency IN LISTS module_DEPENDS)
    target_link_libraries(${target} PUBLIC calligraphy_${dependency})
  endforeach()
  target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:calligraphy_warnings>)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE ${CALLIGRAPHY_UNITY_BATCH_SIZE})
  if(module_PACKAGE STREQUAL "haptics")
    set(CALLIGRAPHY_HAPTICS_MODULES ${CALLIGRAPHY_HAPTICS_MODULES} ${target} CACHE INTERNAL "")
  elseif(module_PACKAGE STREQUAL "research")
    set(CALLIGRAPHY_RESEARCH_MODULES ${CALLIGRAPHY_RESEARCH_MODULES} ${target} CACHE INTERNAL "")
  endif()
endfunction()
