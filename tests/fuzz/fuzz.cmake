# SOAK_FUZZ: the libFuzzer targets only (docs/architecture.md, "Testing"), built with clang into their own build
# folder (scripts/fuzz.sh configures build-fuzz/): the engine's sources with AddressSanitizer and
# the fuzzer's coverage, without the renderer, the program or the test suite.
if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
  message(FATAL_ERROR "SOAK_FUZZ needs clang (configure with -DCMAKE_CXX_COMPILER=clang++)")
endif()
set(SOAK_FUZZ_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer -g -O1)
add_library(soak_fuzz_lib STATIC ${SOAK_SOURCES})
target_include_directories(soak_fuzz_lib PUBLIC ${CMAKE_SOURCE_DIR}/include ${CMAKE_SOURCE_DIR}/src)
target_link_libraries(soak_fuzz_lib PUBLIC Eigen3::Eigen nlohmann_json::nlohmann_json fmt::fmt
                      tinyobjloader::tinyobjloader OpenMP::OpenMP_CXX CGAL::CGAL)
target_compile_options(soak_fuzz_lib PUBLIC ${SOAK_FUZZ_FLAGS} PRIVATE -fsanitize=fuzzer-no-link)
target_link_options(soak_fuzz_lib PUBLIC -fsanitize=address,undefined)
foreach(target scene obj)
  add_executable(fuzz_${target} ${CMAKE_SOURCE_DIR}/tests/fuzz/${target}_fuzz.cpp)
  target_link_libraries(fuzz_${target} PRIVATE soak_fuzz_lib)
  target_compile_options(fuzz_${target} PRIVATE -fsanitize=fuzzer)
  target_link_options(fuzz_${target} PRIVATE -fsanitize=fuzzer)
  target_compile_definitions(fuzz_${target} PRIVATE SOAK_SOURCE_DIR="${CMAKE_SOURCE_DIR}")
endforeach()
