# Builds a target that must not compile and checks how: it fails, the compiler's diagnostics contain the
# expected message, and they are short (a reader sees the message, not a cascade after it).
#   cmake -DBUILD_DIR=... -DTARGET=... -DDIAGNOSTICS=<file the launcher writes> -DEXPECT=<regex>
#         -DMAX_LINES=<n> -P check_refused.cmake
foreach(variable BUILD_DIR TARGET DIAGNOSTICS EXPECT MAX_LINES)
  if(NOT DEFINED ${variable})
    message(FATAL_ERROR "check_refused.cmake: -D${variable}=... is required")
  endif()
endforeach()
file(REMOVE ${DIAGNOSTICS})
execute_process(COMMAND ${CMAKE_COMMAND} --build ${BUILD_DIR} --target ${TARGET}
  RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
if(result EQUAL 0)
  message(FATAL_ERROR "${TARGET} compiled; it must be refused")
endif()
if(NOT EXISTS ${DIAGNOSTICS})
  message(FATAL_ERROR "${TARGET} failed before its compiler ran (no ${DIAGNOSTICS}):\n${output}")
endif()
file(READ ${DIAGNOSTICS} diagnostics)
string(REGEX MATCHALL "\n" newlines "${diagnostics}")
list(LENGTH newlines line_count)
message(STATUS "${TARGET}: the compiler's diagnostics are ${line_count} lines:\n${diagnostics}")
if(NOT diagnostics MATCHES "${EXPECT}")
  message(FATAL_ERROR "${TARGET}: the diagnostics do not say \"${EXPECT}\"")
endif()
if(line_count GREATER MAX_LINES)
  message(FATAL_ERROR "${TARGET}: ${line_count} lines of diagnostics, more than ${MAX_LINES}")
endif()
