# Every external dependency, found once. All come from Debian 12 packages listed in
# scripts/debian-packages.txt. Imported targets that the packages do not provide are
# wrapped here so that the rest of the build links to loom::dep::<name> only.

find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(embree 3 REQUIRED)
find_package(octomap REQUIRED)
find_package(dynamicEDT3D REQUIRED)
find_package(fcl REQUIRED)
find_package(ompl REQUIRED)
find_package(OpenCASCADE REQUIRED)
find_package(assimp REQUIRED)
find_package(pugixml REQUIRED)
find_package(tomlplusplus REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CGAL REQUIRED)
find_package(nanoflann REQUIRED)
find_package(PNG REQUIRED)
find_library(LOOM_LZF_LIBRARY lzf REQUIRED)
find_path(LOOM_LZF_INCLUDE_DIR liblzf/lzf.h REQUIRED)

function(loom_wrap name)
  cmake_parse_arguments(W "" "" "INCLUDES;LIBS" ${ARGN})
  add_library(loom_dep_${name} INTERFACE)
  add_library(loom::dep::${name} ALIAS loom_dep_${name})
  if(W_INCLUDES)
    target_include_directories(loom_dep_${name} SYSTEM INTERFACE ${W_INCLUDES})
  endif()
  if(W_LIBS)
    target_link_libraries(loom_dep_${name} INTERFACE ${W_LIBS})
  endif()
endfunction()

loom_wrap(octomap INCLUDES ${OCTOMAP_INCLUDE_DIRS} LIBS ${OCTOMAP_LIBRARIES})
loom_wrap(edt3d INCLUDES ${DYNAMICEDT3D_INCLUDE_DIRS} LIBS ${DYNAMICEDT3D_LIBRARIES} ${OCTOMAP_LIBRARIES})
loom_wrap(lzf INCLUDES ${LOOM_LZF_INCLUDE_DIR} LIBS ${LOOM_LZF_LIBRARY})
loom_wrap(ompl INCLUDES ${OMPL_INCLUDE_DIRS} LIBS ${OMPL_LIBRARIES})
# OpenCASCADE: the toolkits loom uses (STEP/IGES/XCAF in, meshing, Booleans, STEP out).
loom_wrap(occt INCLUDES ${OpenCASCADE_INCLUDE_DIR}
  LIBS TKernel TKMath TKG2d TKG3d TKGeomBase TKBRep TKGeomAlgo TKTopAlgo TKPrim TKShHealing
       TKMesh TKBO TKBool TKFillet TKOffset TKXSBase TKSTEP TKSTEPBase TKSTEPAttr TKSTEP209
       TKIGES TKLCAF TKCAF TKCDF TKXCAF TKXDESTEP TKXDEIGES TKV3d TKService)

if(LOOM_BUILD_APP)
  find_package(CLI11 REQUIRED)
  # `mpirun -np K loom audit`: the command line shards an audit over MPI ranks (Open MPI).
  find_package(MPI REQUIRED COMPONENTS CXX)
endif()
if(LOOM_BUILD_TESTS)
  find_package(GTest REQUIRED)
  find_package(rapidcheck REQUIRED)
endif()
if(LOOM_BUILD_BENCH)
  find_package(benchmark REQUIRED)
endif()
