# hfmpm_warnings: an interface target every project target links privately.
add_library(hfmpm_warnings INTERFACE)
target_compile_options(hfmpm_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast
  -Wcast-align -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion
  -Wformat=2 -Wimplicit-fallthrough)

add_library(hfmpm_sanitize INTERFACE)
if(HFMPM_SANITIZE)
  target_compile_options(hfmpm_sanitize INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(hfmpm_sanitize INTERFACE -fsanitize=address,undefined)
endif()

option(HFMPM_WERROR "Treat compiler warnings as errors (CI: tools/bootstrap.sh test)" OFF)
if(HFMPM_WERROR)
  target_compile_options(hfmpm_warnings INTERFACE -Werror)
endif()

# hfmpm_options: warnings + sanitizers, for project code (not generated code).
add_library(hfmpm_options INTERFACE)
target_link_libraries(hfmpm_options INTERFACE hfmpm_warnings hfmpm_sanitize)

# GCC 12 reports -Wrestrict inside libstdc++'s std::string at -O3 for ordinary
# string concatenation (GCC bug 105651, a false positive); keep the rest.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(hfmpm_warnings INTERFACE -Wno-restrict)
endif()
