# Each mover is compiled in one object file of the libraries, programs, Python module and
# plugin: the registries are compiled (src/registry.cpp, src/parallel.cpp) and every other
# object sees extern template declarations. Fails naming the objects that define a mover's
# setup() a second time. Variables: BUILD_DIR, NM.
cmake_minimum_required(VERSION 3.20)

file(GLOB_RECURSE objects RELATIVE "${BUILD_DIR}" "${BUILD_DIR}/*.o")
list(FILTER objects EXCLUDE REGEX "^(tests|benchmarks)/")
if(NOT objects)
  message(FATAL_ERROR "check_instantiations: no object files under ${BUILD_DIR} (build first)")
endif()
set(movers RbfMover DgmMover ImprovedDgmMover DgrbfMover Dgrbf2Mover SpringMover TorsionSpringMover ElasticityMover
           NonlinearElasticityMover BlendMover BoundaryOnlyMover parallel::DistributedRbfMover
           parallel::DistributedElasticityMover)
set(failed "")
set(checked 0)
foreach(object ${objects})
  execute_process(COMMAND "${NM}" -C --defined-only "${BUILD_DIR}/${object}" OUTPUT_VARIABLE symbols ERROR_QUIET)
  foreach(mover ${movers})
    foreach(dim 2 3)
      # setup(mesh, boundary), or setup<Mesh<Dim>>(...) where setup is a template over the mesh type
      # (a program's own mesh type, setup<solver::AirfoilGrid>, is that program's instantiation).
      if(symbols MATCHES "meshmotion::${mover}<${dim}>::setup(\\(|<meshmotion::)")
        list(APPEND defined_${dim}_${mover} "${object}")
      endif()
    endforeach()
  endforeach()
  math(EXPR checked "${checked} + 1")
endforeach()
foreach(mover ${movers})
  foreach(dim 2 3)
    list(LENGTH defined_${dim}_${mover} count)
    if(count GREATER 1)
      string(REPLACE ";" "\n  " where "${defined_${dim}_${mover}}")
      string(APPEND failed "${mover}<${dim}>::setup is defined in ${count} objects:\n  ${where}\n")
    endif()
  endforeach()
endforeach()
if(failed)
  message(FATAL_ERROR "check_instantiations: a mover compiled more than once (include the registries, not the movers):\n${failed}")
endif()
message("check_instantiations: ${checked} objects, each mover's setup defined in one at most")
