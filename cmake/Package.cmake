# The installed package (cmake --install build --prefix P), found by
# find_package(kmbvh 0.2 REQUIRED) as two targets:
#   kmbvh::kmbvh   libkmbvh.so: the builders, Bvh, metrics, validation, the layouts and the
#                  traversal (adapters/kmbvh.h includes their headers); no loaders, CLI11
#                  or OpenImageIO
#   kmbvh::embree  libkmbvh_embree.so: Embree's builder API served by kmbvh, and the
#                  one-line swap header (kmbvh/embree_swap.h)
# plus libkmbvh_preload.so (LD_PRELOAD into an unmodified Embree application) and, with
# the tools, the kmbvh command (and libkmbvh_image_io.so, the module it writes images with). Headers go under P/include/kmbvh, in the source tree's
# folders, so that they include one another as they do here.
include(CMakePackageConfigHelpers)
include(GNUInstallDirs)

# The object files of the static libraries the tools link, once more as one shared library
# (their own dependencies stay private to it).
set(_kmbvh_parts kmbvh_core kmbvh_portable_cpu kmbvh_builders kmbvh_traversal kmbvh_triangles kmbvh_layouts)
if(KMBVH_HAS_CUDA)
  list(APPEND _kmbvh_parts kmbvh_portable_gpu)
endif()
list(TRANSFORM _kmbvh_parts REPLACE "(.+)" "$<TARGET_OBJECTS:\\1>" OUTPUT_VARIABLE _kmbvh_objects)
add_library(kmbvh_library SHARED adapters/kmbvh.cpp ${_kmbvh_objects})
target_link_libraries(kmbvh_library PRIVATE fmt::fmt OpenMP::OpenMP_CXX)
if(KMBVH_HAS_CUDA)
  target_link_libraries(kmbvh_library PRIVATE CUDA::cudart_static)
endif()
if(NOT KMBVH_SANITIZERS AND NOT KMBVH_FUZZ)
  # Instrumented builds leave the sanitizer runtime to the executable (as plugin/ does).
  target_link_options(kmbvh_library PRIVATE -Wl,--no-undefined)
endif()
target_include_directories(kmbvh_library PUBLIC
  "$<BUILD_INTERFACE:${PROJECT_SOURCE_DIR};${PROJECT_BINARY_DIR}/include>"
  "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR};${CMAKE_INSTALL_INCLUDEDIR}/kmbvh>")
set_target_properties(kmbvh_library PROPERTIES OUTPUT_NAME kmbvh EXPORT_NAME kmbvh VERSION ${PROJECT_VERSION}
                                               SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
# The ray-triangle test is compiled into the library, but a caller's own code that includes
# it (watertight.h) must not contract it into fused multiply-adds either (cuda/CMakeLists.txt).
target_compile_options(kmbvh_library INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-ffp-contract=off>)
target_compile_features(kmbvh_library INTERFACE cxx_std_17)
kmbvh_warnings(kmbvh_library)
add_library(kmbvh::kmbvh ALIAS kmbvh_library)

set_target_properties(kmbvh_embree PROPERTIES EXPORT_NAME embree VERSION ${PROJECT_VERSION}
                                              SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
target_include_directories(kmbvh_embree PUBLIC "$<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>")

install(TARGETS kmbvh_library kmbvh_embree EXPORT kmbvhTargets
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS kmbvh_preload LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
if(KMBVH_TOOLS)
  install(TARGETS kmbvh RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  # The image codec the tool opens on its first image (adapters/render/image_io).
  install(TARGETS kmbvh_image_io LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
endif()

set(_kmbvh_headers ${CMAKE_INSTALL_INCLUDEDIR}/kmbvh)
install(DIRECTORY cuda/ DESTINATION ${_kmbvh_headers}/cuda FILES_MATCHING PATTERN "*.h" PATTERN "*.inl")
install(DIRECTORY adapters/out/ DESTINATION ${_kmbvh_headers}/adapters/out FILES_MATCHING PATTERN "*.h")
install(FILES adapters/triangles/triangle_scene.h DESTINATION ${_kmbvh_headers}/adapters/triangles)
install(FILES adapters/kmbvh.h ${PROJECT_BINARY_DIR}/include/kmbvh/version.h plugin/include/kmbvh/embree.h
              plugin/include/kmbvh/embree_swap.h DESTINATION ${_kmbvh_headers})

install(EXPORT kmbvhTargets NAMESPACE kmbvh:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kmbvh)
configure_package_config_file(cmake/kmbvhConfig.cmake.in ${PROJECT_BINARY_DIR}/kmbvhConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kmbvh)
# 0.x: a minor version may change the API, so 0.2 is found only by a request for 0.2.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/kmbvhConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/kmbvhConfig.cmake ${PROJECT_BINARY_DIR}/kmbvhConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/kmbvh)
install(FILES LICENSE README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
