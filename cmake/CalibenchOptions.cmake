# One place for the language standard, warnings and build-speed options of every Calibench target.
function(calibench_target_options target)
  target_compile_features(${target} PUBLIC cxx_std_20)
  set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-unused-parameter)
  if(CALIBENCH_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

# ccache shortens rebuilds a lot on 2 cores; use it when the machine has it. Paths under the
# source tree are hashed relative to it (and the build folder not at all), so that another clone
# of the same sources on the machine (a fresh clone's check, CI) reuses what this one compiled.
find_program(CALIBENCH_CCACHE ccache)
if(CALIBENCH_CCACHE)
  set(CMAKE_CXX_COMPILER_LAUNCHER ${CMAKE_COMMAND} -E env CCACHE_BASEDIR=${PROJECT_SOURCE_DIR}
      CCACHE_NOHASHDIR=1 ${CALIBENCH_CCACHE} CACHE STRING "" FORCE)
endif()
