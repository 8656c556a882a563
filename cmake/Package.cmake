# A relocatable package (`cmake --install` + CPack TXZ) that runs with only an NVIDIA driver:
# binaries find their libraries through RPATH $ORIGIN/../lib, and every shared library they
# need except the C library's own (glibc, libm, ld.so) travels in lib/. The CUDA runtime is
# linked statically, so libcuda (the driver) is the one library the machine must provide.
set(_envgi_programs envgi_cli)
if(TARGET envgi_gpu_tests)
  list(APPEND _envgi_programs envgi_gpu_tests)
endif()
if(TARGET envgi_bench_gpu)
  list(APPEND _envgi_programs envgi_bench_gpu)
endif()
if(TARGET envgi_cuda_check)
  list(APPEND _envgi_programs envgi_cuda_check)
endif()
set_target_properties(${_envgi_programs} PROPERTIES INSTALL_RPATH "$ORIGIN/../lib" BUILD_WITH_INSTALL_RPATH OFF)
# DT_RPATH rather than DT_RUNPATH: it also applies to the libraries' own dependencies
# (OpenEXR's Imath, Iex, zlib), which have no RPATH of their own.
foreach(_p IN LISTS _envgi_programs)
  target_link_options(${_p} PRIVATE "LINKER:--disable-new-dtags")
endforeach()
install(TARGETS ${_envgi_programs}
  RUNTIME_DEPENDENCIES
    PRE_EXCLUDE_REGEXES "^(libc|libm|libdl|libpthread|librt|ld-linux.*|linux-vdso|libcuda)\\.so.*"
    POST_EXCLUDE_REGEXES "/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*|libcuda)\\.so[^/]*$"
    DIRECTORIES /usr/lib/x86_64-linux-gnu /lib/x86_64-linux-gnu
  RUNTIME DESTINATION bin
  LIBRARY DESTINATION lib)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/scenes/ DESTINATION share/envgi/scenes)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION share/envgi)

# xz, not gzip: the three GPU programs each carry every kernel, which xz packs into 34 MB where
# gzip took 51 (stop 41), and the device tool carries 64 MB at most.
set(CPACK_GENERATOR TXZ)
set(CPACK_THREADS 0)
set(CPACK_PACKAGE_NAME envgi)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
if(ENVGI_HAS_CUDA)
  set(CPACK_SYSTEM_NAME linux-x86_64-cuda)
else()
  set(CPACK_SYSTEM_NAME linux-x86_64)
endif()
set(CPACK_ARCHIVE_COMPONENT_INSTALL OFF)
set(CPACK_INCLUDE_TOPLEVEL_DIRECTORY ON)
include(CPack)
