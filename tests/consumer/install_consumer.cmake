# cmake -P script behind the InstallConsumer test (see CMakeLists.txt for the -D arguments):
#   1. cmake --install the build into PREFIX (a fresh directory),
#   2. configure and build the consumer project against PREFIX only,
#   3. run the consumer and the installed `sgbake --version`.
# Every step must succeed; a failure prints the step's full output.
cmake_minimum_required(VERSION 3.20)

foreach(var BUILD_DIR CONFIG PREFIX SOURCE_DIR WORK_DIR GENERATOR CXX_COMPILER EXPECTED_VERSION)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "install_consumer.cmake: pass -D ${var}=...")
  endif()
endforeach()

# Runs one step; stops with its output if it fails, and returns its stdout in <out_var>.
function(run_step name out_var)
  execute_process(COMMAND ${ARGN}
    RESULT_VARIABLE result OUTPUT_VARIABLE output ERROR_VARIABLE output)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "InstallConsumer: ${name} failed (${result}):\n${output}")
  endif()
  message(STATUS "InstallConsumer: ${name}: ok")
  set(${out_var} "${output}" PARENT_SCOPE)
endfunction()

# Start from nothing, so that nothing left over from an earlier run can make this pass.
file(REMOVE_RECURSE "${PREFIX}" "${WORK_DIR}")

run_step("install into ${PREFIX}" ignored
  "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}" --config "${CONFIG}")

run_step("configure consumer" ignored
  "${CMAKE_COMMAND}" -S "${SOURCE_DIR}" -B "${WORK_DIR}" -G "${GENERATOR}"
    "-DCMAKE_BUILD_TYPE=${CONFIG}"
    "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}"
    "-DCMAKE_C_FLAGS=${CONSUMER_FLAGS}"
    "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}"
    "-DCMAKE_PREFIX_PATH=${PREFIX}"
    # Only the prefix: never a package registry entry or an sgbake_DIR from somewhere else.
    -DCMAKE_FIND_PACKAGE_NO_PACKAGE_REGISTRY=ON
    -DCMAKE_FIND_PACKAGE_NO_SYSTEM_PACKAGE_REGISTRY=ON
    "-DSGBAKE_EXPECTED_PREFIX=${PREFIX}"
    "-DSGBAKE_EXPECTED_VERSION=${EXPECTED_VERSION}")

run_step("build consumer" ignored "${CMAKE_COMMAND}" --build "${WORK_DIR}" --config "${CONFIG}")

run_step("run consumer" consumer_output "${WORK_DIR}/sgbake_consumer")
message(STATUS "${consumer_output}")

# The installed tool must run from its prefix (it finds libsgbake through its RPATH).
run_step("run installed sgbake --version" version_output "${PREFIX}/bin/sgbake" --version)

# The Blender add-on is installed with a note of where this installation's library is.
set(addon "${PREFIX}/share/sgbake/blender/sgbake_blender")
foreach(file __init__.py capi.py installed_library.py)
  if(NOT EXISTS "${addon}/${file}")
    message(FATAL_ERROR "InstallConsumer: the add-on's ${file} is not installed in ${addon}")
  endif()
endforeach()
file(STRINGS "${addon}/installed_library.py" library_line REGEX "^LIBRARY = ")
string(REGEX REPLACE "^LIBRARY = \"(.*)\"$" "\\1" library_relative "${library_line}")
get_filename_component(library "${addon}/${library_relative}" ABSOLUTE)
if(NOT EXISTS "${library}")
  message(FATAL_ERROR "InstallConsumer: the add-on's installed_library.py names ${library}, "
                      "which does not exist")
endif()
message(STATUS "InstallConsumer: the installed add-on finds ${library}: ok")
if(NOT version_output STREQUAL "sgbake ${EXPECTED_VERSION}\n")
  message(FATAL_ERROR "InstallConsumer: installed sgbake --version printed '${version_output}'")
endif()
