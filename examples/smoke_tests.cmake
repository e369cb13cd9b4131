# Smoke tests of the example programs (label "examples"): every program answers --help, and
# each runs once on small inputs with --json, must exit with the expected code and print one
# JSON object holding the keys its documented output promises. The command-line programs
# work on meshes they make themselves: curve_mesh's built-in demo (a fixture), then
# mesh_info, mesh_quality and move_mesh on its output.
#
# This file is also the checker the tests run, in CMake script mode:
#   cmake -DKEYS=a,b/c [-DEXPECT_RC=n] -P smoke_tests.cmake -- <program> <arguments...>
# KEYS are JSON paths ("/" between nested keys) that must exist in the program's stdout.

if(CMAKE_SCRIPT_MODE_FILE)
  set(command "")
  set(after_separator FALSE)
  math(EXPR last "${CMAKE_ARGC} - 1")
  foreach(i RANGE ${last})
    if(after_separator)
      list(APPEND command "${CMAKE_ARGV${i}}")
    elseif(CMAKE_ARGV${i} STREQUAL "--")
      set(after_separator TRUE)
    endif()
  endforeach()
  list(LENGTH command length)
  if(length EQUAL 0)
    message(FATAL_ERROR "smoke_tests.cmake: no program given (expected -- <program> <arguments...>)")
  endif()
  if(NOT DEFINED EXPECT_RC)
    set(EXPECT_RC 0)
  endif()
  execute_process(COMMAND ${command} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(REPLACE ";" " " shown "${command}")
  if(NOT rc STREQUAL "${EXPECT_RC}")
    message(FATAL_ERROR "${shown}\nexit code ${rc} (expected ${EXPECT_RC})\nstdout:\n${out}\nstderr:\n${err}")
  endif()
  string(REPLACE "," ";" keys "${KEYS}")
  foreach(key ${keys})
    string(REPLACE "/" ";" path "${key}")
    string(JSON value ERROR_VARIABLE problem GET "${out}" ${path})
    if(problem)
      message(FATAL_ERROR "${shown}\nJSON key '${key}' missing or output not JSON: ${problem}\nstdout:\n${out}")
    endif()
    message(STATUS "${key} = ${value}")
  endforeach()
  return()
endif()

if(NOT MESHMOTION_BUILD_TESTS)
  return()
endif()

set(smoke_dir "${CMAKE_CURRENT_BINARY_DIR}/smoke")
file(MAKE_DIRECTORY "${smoke_dir}")
set(smoke_checker "${CMAKE_CURRENT_LIST_FILE}")

# smoke_test(NAME name KEYS a,b/c [EXPECT_RC n] [SETUP fixture] [REQUIRES fixtures...]
#            COMMAND program args...)
function(smoke_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;KEYS;EXPECT_RC;SETUP" "REQUIRES;COMMAND")
  if(NOT DEFINED arg_EXPECT_RC)
    set(arg_EXPECT_RC 0)
  endif()
  list(POP_FRONT arg_COMMAND program)
  add_test(NAME examples.${arg_NAME}
           COMMAND "${CMAKE_COMMAND}" -DKEYS=${arg_KEYS} -DEXPECT_RC=${arg_EXPECT_RC} -P "${smoke_checker}"
                   -- $<TARGET_FILE:${program}> ${arg_COMMAND}
           WORKING_DIRECTORY "${smoke_dir}")
  set_tests_properties(examples.${arg_NAME} PROPERTIES LABELS examples)
  if(arg_SETUP)
    set_tests_properties(examples.${arg_NAME} PROPERTIES FIXTURES_SETUP ${arg_SETUP})
  endif()
  if(arg_REQUIRES)
    set_tests_properties(examples.${arg_NAME} PROPERTIES FIXTURES_REQUIRED "${arg_REQUIRES}")
  endif()
endfunction()

# --help of every program (new examples are covered as they are added).
foreach(source ${example_sources})
  get_filename_component(program ${source} NAME_WE)
  add_test(NAME examples.${program}.help COMMAND ${program} --help)
  set_tests_properties(examples.${program}.help PROPERTIES LABELS examples PASS_REGULAR_EXPRESSION "Usage:")
endforeach()

# The tutorials, on small meshes and few steps.
smoke_test(NAME tutorial_1_time_loop.json
           KEYS nodes,setups,moves,setup_seconds,seconds_per_move,lowest_min_skew,final_min_scaled_jacobian,invalid_steps
           COMMAND tutorial_1_time_loop --steps 60 --period-steps 30 --n-around 48 --n-radial 16 --json)
smoke_test(NAME tutorial_2_optimization_loop.json
           KEYS objective_start,objective_final,iterations/0/reverse,iterations/0/finite_difference,max_relative_difference,gradient_check_passed
           COMMAND tutorial_2_optimization_loop --n-around 32 --n-radial 10 --iterations 2 --json)
smoke_test(NAME adapt_solver_mesh.json
           KEYS nodes,triangles,edges,boundary_edges,max_node_degree,copied_cells
           COMMAND adapt_solver_mesh --nx 8 --ny 4 --json)

# The command-line programs on the mesh curve_mesh generates.
smoke_test(NAME curve_mesh.demo.json SETUP examples_demo_mesh
           KEYS output,nodes,cells,min_scaled_jacobian,invalid,seconds/total
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo.msh" --json)
smoke_test(NAME mesh_info.json REQUIRES examples_demo_mesh
           KEYS file,mesh/nodes,mesh/cells,mesh/groups
           COMMAND mesh_info "${smoke_dir}/demo.msh" --json)
smoke_test(NAME mesh_quality.json REQUIRES examples_demo_mesh
           KEYS nodes,elements,metrics/skew/min,metrics/scaled_jacobian/invalid
           COMMAND mesh_quality "${smoke_dir}/demo.msh" --metric skew --metric jacobian --json)
smoke_test(NAME move_mesh.json REQUIRES examples_demo_mesh SETUP examples_moved_mesh
           KEYS output,setup_seconds,move_seconds,before/min,after/min,after/invalid
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved.msh" --group wall --rotate 5
                   --fixed farfield --json)
smoke_test(NAME mesh_info.moved.json REQUIRES examples_moved_mesh
           KEYS file,mesh/nodes,mesh/cells
           COMMAND mesh_info "${smoke_dir}/moved.msh" --json)

# The mechanics knobs reach the mover: stiffened elasticity as curve_mesh's regularizer and
# as move_mesh's mover, and a bad Poisson ratio is refused.
smoke_test(NAME curve_mesh.sle.json
           KEYS output,min_scaled_jacobian,invalid,seconds/total
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_sle.msh" --method sle --stiffening-exponent 2
                   --poisson-ratio 0.4 --youngs-modulus 1e6 --solver simplicial_llt --json)
smoke_test(NAME move_mesh.sle.json REQUIRES examples_demo_mesh
           KEYS output,after/min,after/invalid
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_sle.msh" --group wall --rotate 2
                   --fixed farfield --method sle --stiffening-exponent 1.5 --poisson-ratio 0.35 --json)
smoke_test(NAME curve_mesh.bad_poisson_ratio.json EXPECT_RC 1
           KEYS error
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_bad.msh" --method sle --poisson-ratio 0.7 --json)

# The blending regularizer with its length in wall layers; a length factor must be positive.
smoke_test(NAME curve_mesh.blend.json
           KEYS output,min_scaled_jacobian,invalid
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_blend.msh" --method blend --blending-factor 4 --json)
smoke_test(NAME curve_mesh.bad_blending_factor EXPECT_RC 105
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_bad_blend.msh" --method blend --blending-factor 0)

# SVG pictures: invalid cells ringed (the default) or not; snapping alone leaves invalid cells.
smoke_test(NAME curve_mesh.svg_no_markers.json
           KEYS output,min_scaled_jacobian,invalid
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_none.msh" --method none --svg "${smoke_dir}/demo_none.svg"
                   --zoom -0.8,0.8,-0.8,0.8 --svg-no-markers --json)
smoke_test(NAME mesh_quality.svg_no_markers.json REQUIRES examples_demo_mesh
           KEYS nodes,elements,metrics/scaled_jacobian/invalid
           COMMAND mesh_quality "${smoke_dir}/demo.msh" --metric jacobian --svg "${smoke_dir}/demo_quality.svg"
                   --svg-no-markers --json)

# Bad input: a clear error, in JSON too, and a non-zero exit.
smoke_test(NAME mesh_info.missing_file.json EXPECT_RC 1
           KEYS error
           COMMAND mesh_info "${smoke_dir}/no_such_mesh.msh" --json)
