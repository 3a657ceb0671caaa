# Run by `cmake --install` (component python): writes calligraphy.pth into the site-packages folder of a
# second interpreter of the same major.minor (a pyenv `python3` first on PATH), so that it finds the
# installed package and the build interpreter's own folders, where numpy and the other Debian packages
# are. Python's `site` adds each existing line of a .pth file to sys.path, after the interpreter's own
# folders, so its own packages still come first.
#
# Set by the install(CODE) that includes this file (each may be given with -D to `cmake -P
# cmake_install.cmake` instead, e.g. by the install test):
#   CALLIGRAPHY_PYTHON_PTH_DIR      the folder to write calligraphy.pth into ("" for none)
#   calligraphy_module_dir          where the package is installed (relative to CMAKE_INSTALL_PREFIX or absolute)
#   calligraphy_build_site_dirs     the build interpreter's site folders (a CMake list)
#   calligraphy_pth_staging         a scratch file in the build tree
if(CALLIGRAPHY_PYTHON_PTH_DIR STREQUAL "")
  return()
endif()
if(IS_ABSOLUTE "${calligraphy_module_dir}")
  set(module_path "${calligraphy_module_dir}")
else()
  set(module_path "${CMAKE_INSTALL_PREFIX}/${calligraphy_module_dir}")
endif()
set(lines "${module_path}" ${calligraphy_build_site_dirs})
list(REMOVE_DUPLICATES lines)
list(JOIN lines "\n" body)
get_filename_component(staging_dir "${calligraphy_pth_staging}" DIRECTORY)
file(MAKE_DIRECTORY "${staging_dir}")
file(WRITE "${calligraphy_pth_staging}"
  "# Written by calligraphy's `cmake --install --component python`: the folders of the calligraphy\n"
  "# package and of the interpreter it was built for (numpy). Delete this file to undo.\n"
  "${body}\n")
message(STATUS "calligraphy: ${CALLIGRAPHY_PYTHON_PTH_DIR}/calligraphy.pth puts ${module_path} and the build "
               "interpreter's site folders on that interpreter's sys.path (-DCALLIGRAPHY_PYTHON_PTH_DIR= at "
               "configure time for none)")
# file(INSTALL) honours DESTDIR and lists the file in install_manifest.txt.
file(INSTALL DESTINATION "${CALLIGRAPHY_PYTHON_PTH_DIR}" TYPE FILE RENAME calligraphy.pth
  FILES "${calligraphy_pth_staging}")
