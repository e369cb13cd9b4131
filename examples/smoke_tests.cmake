# Smoke tests of the example programs (label "examples"): every program answers --help, and
# each runs once on small inputs with --json, must exit with the expected code and print one
# JSON object holding the keys its documented output promises. The command-line programs
# work on meshes they make themselves: curve_mesh's built-in demo (a fixture), then
# mesh_info, mesh_quality and move_mesh on its output.
#
# This file is also the checker the tests run, in CMake script mode:
#   cmake -DKEYS=a,b/c [-DVALUES=a/b=text,...] [-DAT_LEAST=a/b=number,...] [-DEXPECT_RC=n]
#         [-DSTDERR_NOT=regex] -P smoke_tests.cmake -- <program> <arguments...>
# KEYS are JSON paths ("/" between nested keys) that must exist in the program's stdout;
# VALUES are paths whose value must read exactly as the text given; AT_LEAST paths whose
# number must be at least the one given; STDERR_NOT a pattern stderr must not match.

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_policy(SET CMP0054 NEW)  # "VALUES" below is text, not the variable
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
  if(STDERR_NOT AND err MATCHES "${STDERR_NOT}")
    message(FATAL_ERROR "${shown}\nstderr matches '${STDERR_NOT}':\n${err}")
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
  foreach(check VALUES AT_LEAST)
    string(REPLACE "," ";" values "${${check}}")
    foreach(pair ${values})
      string(FIND "${pair}" "=" eq)
      string(SUBSTRING "${pair}" 0 ${eq} key)
      math(EXPR after "${eq} + 1")
      string(SUBSTRING "${pair}" ${after} -1 expected)
      string(REPLACE "/" ";" path "${key}")
      string(JSON value ERROR_VARIABLE problem GET "${out}" ${path})
      if(check STREQUAL "VALUES" AND (problem OR NOT value STREQUAL expected))
        message(FATAL_ERROR "${shown}\nJSON key '${key}' is '${value}' (expected '${expected}')\nstdout:\n${out}")
      elseif(check STREQUAL "AT_LEAST" AND (problem OR value LESS expected))
        message(FATAL_ERROR "${shown}\nJSON key '${key}' is '${value}' (expected at least ${expected})\nstdout:\n${out}")
      endif()
    endforeach()
  endforeach()
  return()
endif()

if(NOT MESHMOTION_BUILD_TESTS)
  return()
endif()

set(smoke_dir "${CMAKE_CURRENT_BINARY_DIR}/smoke")
file(MAKE_DIRECTORY "${smoke_dir}")
set(smoke_checker "${CMAKE_CURRENT_LIST_FILE}")

# smoke_test(NAME name KEYS a,b/c [VALUES a/b=text,...] [EXPECT_RC n] [SETUP fixture]
#            [REQUIRES fixtures...] [RANKS n] [AT_LEAST a/b=number,...] COMMAND program args...)
# RANKS runs the program under mpiexec with n ranks.
function(smoke_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;KEYS;VALUES;AT_LEAST;EXPECT_RC;SETUP;RANKS;STDERR_NOT" "REQUIRES;COMMAND")
  if(NOT DEFINED arg_EXPECT_RC)
    set(arg_EXPECT_RC 0)
  endif()
  list(POP_FRONT arg_COMMAND program)
  set(launcher)
  if(arg_RANKS)
    meshmotion_mpiexec_flags(mpi_flags)
    set(launcher ${MESHMOTION_MPIEXEC} ${mpi_flags} -n ${arg_RANKS})
  endif()
  add_test(NAME examples.${arg_NAME}
           COMMAND "${CMAKE_COMMAND}" -DKEYS=${arg_KEYS} "-DVALUES=${arg_VALUES}" "-DAT_LEAST=${arg_AT_LEAST}"
                   -DEXPECT_RC=${arg_EXPECT_RC} "-DSTDERR_NOT=${arg_STDERR_NOT}"
                   -P "${smoke_checker}"
                   -- ${launcher} $<TARGET_FILE:${program}> ${arg_COMMAND}
           WORKING_DIRECTORY "${smoke_dir}")
  set_tests_properties(examples.${arg_NAME} PROPERTIES LABELS examples)
  if(arg_RANKS)
    set_tests_properties(examples.${arg_NAME} PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1" RUN_SERIAL TRUE)
  endif()
  if(arg_SETUP)
    set_tests_properties(examples.${arg_NAME} PROPERTIES FIXTURES_SETUP ${arg_SETUP})
  endif()
  if(arg_REQUIRES)
    set_tests_properties(examples.${arg_NAME} PROPERTIES FIXTURES_REQUIRED "${arg_REQUIRES}")
  endif()
endfunction()

# --help and --version of every program (new examples are covered as they are added).
foreach(source ${example_sources})
  get_filename_component(program ${source} NAME_WE)
  add_test(NAME examples.${program}.help COMMAND ${program} --help)
  set_tests_properties(examples.${program}.help PROPERTIES LABELS examples PASS_REGULAR_EXPRESSION "Usage:")
  add_test(NAME examples.${program}.version COMMAND ${program} --version)
  set_tests_properties(examples.${program}.version PROPERTIES LABELS examples
                       PASS_REGULAR_EXPRESSION "meshmotion ${PROJECT_VERSION}")
endforeach()

# The tutorials, on small meshes and few steps.
smoke_test(NAME tutorial_1_time_loop.json
           KEYS nodes,setups,moves,setup_seconds,seconds_per_move,lowest_min_skew,final_min_scaled_jacobian,invalid_steps
           COMMAND tutorial_1_time_loop --steps 60 --period-steps 30 --n-around 48 --n-radial 16 --json)
smoke_test(NAME tutorial_2_optimization_loop.json
           KEYS objective_start,objective_final,iterations/0/reverse,iterations/0/finite_difference,max_relative_difference,gradient_check_passed
           COMMAND tutorial_2_optimization_loop --n-around 32 --n-radial 10 --iterations 2 --json)
smoke_test(NAME tutorial_3_grid_velocity.json
           KEYS method,steps,nodes,max_speed,velocity_vs_difference,min_scaled_jacobian
           COMMAND tutorial_3_grid_velocity --steps 10 --period-steps 20 --json)
smoke_test(NAME tutorial_3_grid_velocity.spring.json
           KEYS method,velocity_vs_difference
           COMMAND tutorial_3_grid_velocity --steps 4 --method spring --json)
smoke_test(NAME adapt_solver_mesh.json
           KEYS nodes,triangles,edges,boundary_edges,max_node_degree,copied_cells
           COMMAND adapt_solver_mesh --nx 8 --ny 4 --json)

# The command-line programs on the mesh curve_mesh generates.
smoke_test(NAME curve_mesh.demo.json SETUP examples_demo_mesh
           KEYS output,nodes,cells,min_scaled_jacobian,invalid,seconds/total
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo.msh" --json)
# The last line says what each group was curved onto.
add_test(NAME examples.curve_mesh.demo.curved_on COMMAND curve_mesh --demo -o "${smoke_dir}/demo_text.msh"
         WORKING_DIRECTORY "${smoke_dir}")
set_tests_properties(examples.curve_mesh.demo.curved_on PROPERTIES LABELS examples
                     PASS_REGULAR_EXPRESSION "wrote [^\n]*demo_text.msh[^\n]*\\(curved: 'wall' on the given --geometry, 'farfield' by spline\\)")
# The geometric certificate: with a tolerance no facet meets, the mesh is written, the
# report counts the facets off their geometry, and the program exits 2.
smoke_test(NAME curve_mesh.demo.off_geometry EXPECT_RC 2
           KEYS geometry_distance/0/max_relative_distance,geometry_distance/1/facets_off
           VALUES off_geometry=256,geometry_distance/0/group=wall,geometry_distance/0/geometry=projection
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_off.msh" --geometry-tolerance 1e-9 --json)
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
# --compare: the moved mesh is not the mesh given (exit 2, how far it moved), and a mesh of
# other nodes is refused with both counts.
smoke_test(NAME mesh_info.compare_moved.json REQUIRES examples_moved_mesh EXPECT_RC 2
           KEYS compared/max_difference,compared/relative VALUES compared/within=OFF,compared/tolerance=1e-10
           COMMAND mesh_info "${smoke_dir}/moved.msh" --compare "${smoke_dir}/demo.msh" --json)
smoke_test(NAME mesh_info.compare_other_nodes.json REQUIRES examples_demo_mesh examples_demo_p3 EXPECT_RC 1
           KEYS error VALUES kind=input
           COMMAND mesh_info "${smoke_dir}/demo.msh" --compare "${smoke_dir}/demo_p3.su2" --json)
# move_mesh --steps with the defaults: one setup at rest, each step moved from it (a time
# loop's policy), so the steps end where one move does, and the last step is the third move
# of that setup.
smoke_test(NAME move_mesh.steps_from_one_setup.json REQUIRES examples_demo_mesh SETUP examples_moved_steps
           KEYS mover_steps VALUES steps=3,mover_steps/2/moves=3,mover_steps/2/rigid_part=ON,after/invalid=0
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_steps.msh" --group wall --rotate 60
                   --fixed farfield --steps 3 --json)
smoke_test(NAME move_mesh.one_step_peer.json REQUIRES examples_demo_mesh SETUP examples_moved_one_step
           KEYS after/min VALUES steps=1
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_one_step.msh" --group wall --rotate 60
                   --fixed farfield --json)
smoke_test(NAME move_mesh.steps_equal_one_move.json REQUIRES examples_moved_steps examples_moved_one_step
           KEYS compared/relative VALUES compared/within=ON
           COMMAND mesh_info "${smoke_dir}/moved_steps.msh" --compare "${smoke_dir}/moved_one_step.msh" --json)

# The sphere on its STEP file with no flag but --geometry and --order (../shared/data): the
# symmetry plane, planar, slides by default (fixed it gave 0.61, docs/curving.md), the planar
# far field is already on the model, the minimum reaches the tuned row (0.8560), and every
# curved facet is on the model.
set(sphere_mesh "${MESHMOTION_SHARED_DATA_DIR}/meshopt_sphere_symmetry_linear_tet.msh")
set(sphere_step "${MESHMOTION_SHARED_DATA_DIR}/meshopt_Sphere25CSymmetry.stp")
if(NOT MESHMOTION_HAVE_CAD)
  message(STATUS "examples: no CAD component: the sphere-on-STEP smoke test is skipped")
elseif(NOT EXISTS "${sphere_mesh}" OR NOT EXISTS "${sphere_step}")
  message(STATUS "examples: ${MESHMOTION_SHARED_DATA_DIR} lacks the sphere's mesh and STEP file: its smoke test is skipped")
else()
  smoke_test(NAME curve_mesh.sphere_step.defaults SETUP examples_sphere_p3
             KEYS curved_groups,sliding_groups/0
             VALUES sliding_groups/0=20,invalid=0,off_geometry=0
             AT_LEAST min_scaled_jacobian=0.855
             COMMAND curve_mesh "${sphere_mesh}" -o "${smoke_dir}/sphere_p3.msh" --order 3 --geometry "${sphere_step}" --json)
  # Its .msh places every node of the model's faces and edges on them (3908 of the P3 nodes).
  smoke_test(NAME mesh_info.sphere_p3.on_model REQUIRES examples_sphere_p3
             KEYS mesh/nodes_on_model
             VALUES mesh/nodes_on_model=3908
             COMMAND mesh_info "${smoke_dir}/sphere_p3.msh" --json)
endif()

# Orders past 2: the demo curved at order 3 (and its .su2 in SU2's DG-FEM format read back
# by mesh_info) and at orders 5, 6 and 8, certified valid with a minimum of 0.5 or more;
# order 9 is refused before any work.
smoke_test(NAME curve_mesh.order3.json SETUP examples_demo_p3
           KEYS output,order,min_scaled_jacobian,invalid,untangle/cells_below,seconds/untangle
           VALUES order=3,invalid=0
           COMMAND curve_mesh --demo --order 3 -o "${smoke_dir}/demo_p3.su2" --json)
foreach(order 5 6 8)
  smoke_test(NAME curve_mesh.order${order}.json
             KEYS output,order,min_scaled_jacobian,invalid
             VALUES order=${order},invalid=0
             AT_LEAST min_scaled_jacobian=0.5
             COMMAND curve_mesh --demo --order ${order} -o "${smoke_dir}/demo_p${order}.msh" --json)
endforeach()
# A P5 quadrilateral disk meshed by Gmsh (its element types 38 and 28), turned 20 degrees by
# move_mesh's defaults: certified valid by move_mesh, and by mesh_quality on what it wrote.
find_program(MESHMOTION_GMSH gmsh)
if(MESHMOTION_GMSH)
  file(WRITE "${smoke_dir}/disk_quads_p5.geo"
       "SetFactory(\"OpenCASCADE\");\nDisk(1) = {0, 0, 0, 1};\nPhysical Curve(\"rim\") = {1};\n"
       "Physical Surface(\"disk\") = {1};\nMesh.MeshSizeMax = 0.25;\nMesh.RecombineAll = 1;\n"
       "Mesh.SubdivisionAlgorithm = 1;\nMesh.ElementOrder = 5;\n")
  add_test(NAME examples.gmsh.disk_quads_p5
           COMMAND "${MESHMOTION_GMSH}" -2 disk_quads_p5.geo -o disk_quads_p5.msh -v 1
           WORKING_DIRECTORY "${smoke_dir}")
  set_tests_properties(examples.gmsh.disk_quads_p5 PROPERTIES LABELS examples FIXTURES_SETUP examples_disk_p5)
  smoke_test(NAME move_mesh.disk_p5_turned.json REQUIRES examples_disk_p5 SETUP examples_disk_p5_turned
             KEYS output,after/min,after/invalid
             VALUES after/invalid=0
             COMMAND move_mesh "${smoke_dir}/disk_quads_p5.msh" -o "${smoke_dir}/disk_quads_p5_turned.msh" --group rim
                     --rotate 20 --json)
  smoke_test(NAME mesh_quality.disk_p5_turned.json REQUIRES examples_disk_p5_turned
             KEYS elements,metrics/scaled_jacobian/min,metrics/scaled_jacobian/invalid
             VALUES metrics/scaled_jacobian/invalid=0
             COMMAND mesh_quality "${smoke_dir}/disk_quads_p5_turned.msh" --metric jacobian --json)
else()
  message(STATUS "meshmotion: gmsh not found; the smoke tests on Gmsh's P5 disk are skipped")
endif()
smoke_test(NAME curve_mesh.order9 EXPECT_RC 1
           KEYS error
           COMMAND curve_mesh --demo --order 9 -o "${smoke_dir}/demo_p9.msh" --json)

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
smoke_test(NAME curve_mesh.bad_blending_factor.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_bad_blend.msh" --method blend --blending-factor 0 --json)
# The options come from one description: curve_mesh's JSON echoes every key it ran with, a
# misspelled key is refused naming the known ones, and a key of another method is refused.
smoke_test(NAME curve_mesh.options_echoed.json
           KEYS options/raise_rounds,options/blending_factor,mover_steps/0/setup_seconds,layers
           VALUES options/order=2,options/blending_factor=3,options/midpoint=parameter,options/untangle=false
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_echo.msh" --blending-factor 3 --parameter-midpoint
                   --no-untangle --json)
smoke_test(NAME curve_mesh.misspelled_option.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_typo.msh" --option blending_facter=3 --json)
smoke_test(NAME curve_mesh.option_of_another_method.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_other.msh" --kernel wendland4 --json)

# SVG pictures: invalid cells ringed (the default) or not; snapping alone leaves invalid cells.
smoke_test(NAME curve_mesh.svg_no_markers.json EXPECT_RC 2
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

# No silent wrong answer (issue 17). Small inputs written here: a unit square of two
# triangles listed clockwise in SU2 (every cell negative), and displacement files by node.
file(WRITE "${smoke_dir}/clockwise.su2" "NDIME= 2\nNELEM= 2\n5 0 2 1 0\n5 0 3 2 1\nNPOIN= 4\n0 0 0\n1 0 1\n1 1 2\n0 1 3\n"
     "NMARK= 2\nMARKER_TAG= bottom\nMARKER_ELEMS= 1\n3 0 1\nMARKER_TAG= rest\nMARKER_ELEMS= 3\n3 1 2\n3 2 3\n3 3 0\n")
# The demo's wall: every node of group 'wall' is listed by mesh_info; a file naming a node
# outside the group must be refused, naming it.
file(WRITE "${smoke_dir}/outside_node.txt" "# node dx dy\n1 0.0 0.0\n")
file(WRITE "${smoke_dir}/bad_line.txt" "0.001 0.002\n")

# A consistently reversed mesh is reoriented (and said so), so no cell counts as invalid;
# --keep-orientation refuses it instead.
smoke_test(NAME mesh_quality.reversed.json
           KEYS metrics/scaled_jacobian/min VALUES metrics/scaled_jacobian/invalid=0
           COMMAND mesh_quality "${smoke_dir}/clockwise.su2" --metric jacobian --json)
smoke_test(NAME mesh_quality.keep_orientation.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND mesh_quality "${smoke_dir}/clockwise.su2" --keep-orientation --json)
smoke_test(NAME mesh_info.reversed.json KEYS mesh/negative_cells VALUES mesh/orientation=reversed
           COMMAND mesh_info "${smoke_dir}/clockwise.su2" --json)
smoke_test(NAME move_mesh.reversed.json VALUES after/invalid=0,before/invalid=0
           KEYS output
           COMMAND move_mesh "${smoke_dir}/clockwise.su2" -o "${smoke_dir}/clockwise_moved.su2" --group bottom
                   --translate 0.01,0 --fixed rest --json)

# Options are typed end to end: a misspelled key is refused naming the known ones, a number
# keeps every digit, and a method refuses keys it does not take.
smoke_test(NAME move_mesh.misspelled_option.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_typo.msh" --group wall --rotate 1
                   --fixed farfield --option suport_radius=0.5 --json)
smoke_test(NAME move_mesh.exact_radius.json REQUIRES examples_demo_mesh
           KEYS output VALUES options/support_radius=4.9e-06,options/tolerance=1e-07
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_exact.msh" --group wall --rotate 0.001
                   --fixed farfield --support-radius 4.9e-6 --option tolerance=1e-7 --json)
smoke_test(NAME move_mesh.option_of_another_method.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_other.msh" --group wall --rotate 1
                   --fixed farfield --poisson-ratio 0.3 --json)
smoke_test(NAME move_mesh.malformed_number.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_nan.msh" --group wall --rotate 1
                   --fixed farfield --option support_radius=0.5x --json)

# Displacements by node: lines without a node id and nodes outside the group are refused.
smoke_test(NAME move_mesh.displacements_without_node.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error
           VALUES kind=parse
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_bad.msh" --group wall
                   --displacements "${smoke_dir}/bad_line.txt" --fixed farfield --json)
smoke_test(NAME move_mesh.displacements_outside_group.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_outside.msh" --group farfield
                   --displacements "${smoke_dir}/outside_node.txt" --fixed wall --json)

# A command line the parser refuses is an input error like any other (exit 1, the error object),
# absurd counts included; a device given as a file is refused, never read without end.
smoke_test(NAME mesh_info.unknown_flag.json EXPECT_RC 1 KEYS error VALUES kind=usage
           COMMAND mesh_info --no-such-flag --json)
smoke_test(NAME move_mesh.absurd_steps.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=usage
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_steps.msh" --group wall --rotate 1
                   --fixed farfield --steps 1000000000 --json)
smoke_test(NAME mesh_info.huge_omp_num_threads.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND mesh_info "${smoke_dir}/demo.msh" --json)
set_tests_properties(examples.mesh_info.huge_omp_num_threads.json PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=100000")
if(EXISTS /dev/zero)
  smoke_test(NAME move_mesh.displacements_device.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=io
             COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_zero.msh" --group wall
                     --displacements /dev/zero --fixed farfield --json)
  smoke_test(NAME move_mesh.options_file_device.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=io
             COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_zero.msh" --group wall --rotate 1
                     --options-file /dev/zero --fixed farfield --json)
endif()

# A corrupt CGNS file (a fuzzer's find: the CGNS library fails inside its open) is an io error,
# and HDF5 says nothing at exit (it printed "infinite loop closing library").
if(MESHMOTION_HAVE_CGNS)
  smoke_test(NAME mesh_info.corrupt_cgns.json EXPECT_RC 1 KEYS error VALUES kind=io STDERR_NOT "HDF5|infinite loop"
             COMMAND mesh_info "${PROJECT_SOURCE_DIR}/tests/fuzz/corpus/cgns/regression_failed_open.cgns" --json)
endif()

# A CGNS write that fails (here a file size limit: a full disk alike) is an io error and the
# program exits 1: HDF5 used to crash at exit over the file it could not close.
if(MESHMOTION_HAVE_CGNS)
  add_test(NAME examples.curve_mesh.cgns_write_fails.json
           COMMAND "${CMAKE_COMMAND}" -DKEYS=error -DVALUES=kind=io -DEXPECT_RC=1 -P "${smoke_checker}"
                   -- sh -c "ulimit -f 20 && trap '' XFSZ && exec \"$0\" \"$@\"" $<TARGET_FILE:curve_mesh> --demo
                   -o "${smoke_dir}/size_limit.cgns" --json
           WORKING_DIRECTORY "${smoke_dir}")
  set_tests_properties(examples.curve_mesh.cgns_write_fails.json PROPERTIES LABELS examples)
endif()

# Outputs are checked before any work, and an input is never overwritten unasked.
smoke_test(NAME curve_mesh.svg_in_missing_folder.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_svg_folder.msh" --svg "${smoke_dir}/no_such_folder/demo.svg" --json)
# A picture named as a folder cannot be written: refused before the mesh and its .vtu are
# written (the outputs of a run are written as a set: all, or on an error none).
smoke_test(NAME curve_mesh.svg_is_folder.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_svg_is_folder.msh" --svg "${smoke_dir}" --json)
add_test(NAME examples.curve_mesh.svg_is_folder_wrote_nothing
         COMMAND "${CMAKE_COMMAND}" -E cat "${smoke_dir}/demo_svg_is_folder.vtu")
set_tests_properties(examples.curve_mesh.svg_is_folder_wrote_nothing PROPERTIES LABELS examples WILL_FAIL TRUE
                     DEPENDS examples.curve_mesh.svg_is_folder.json)
# The verdict is the certificate's at every order: a P2 file whose mid-edge node lies beyond
# the opposite vertex (its straight corners are fine) is invalid for every metric, and
# move_mesh --strict writes nothing.
set(folded_p2 "${PROJECT_SOURCE_DIR}/tests/quality/data/folded_p2.msh")
smoke_test(NAME mesh_quality.folded_p2.json KEYS metrics/skew/min
           VALUES metrics/skew/invalid=1,metrics/scaled_jacobian/invalid=1
           COMMAND mesh_quality "${folded_p2}" --metric skew --metric jacobian --json)
smoke_test(NAME move_mesh.folded_p2_strict.json EXPECT_RC 2 KEYS error VALUES kind=invalid_mesh
           COMMAND move_mesh "${folded_p2}" -o "${smoke_dir}/folded_p2_moved.msh" --group wall --translate 0.01,0
                   --fixed rest --method none --strict --json)
add_test(NAME examples.move_mesh.folded_p2_strict_wrote_nothing
         COMMAND "${CMAKE_COMMAND}" -E cat "${smoke_dir}/folded_p2_moved.msh")
set_tests_properties(examples.move_mesh.folded_p2_strict_wrote_nothing PROPERTIES LABELS examples WILL_FAIL TRUE
                     DEPENDS examples.move_mesh.folded_p2_strict.json)

# A picture or a .vtu named as the input (by another path to it), or as another output of the
# run, is refused before anything is read or written; --overwrite lets only the mesh replace
# its input. mesh_info then reads the input as the mesh it was.
smoke_test(NAME mesh_quality.svg_over_input.json REQUIRES examples_demo_mesh SETUP examples_not_overwritten
           EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND mesh_quality "${smoke_dir}/demo.msh" --svg "${smoke_dir}/./demo.msh" --json)
smoke_test(NAME mesh_quality.vtu_over_input.json REQUIRES examples_demo_mesh SETUP examples_not_overwritten
           EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND mesh_quality "${smoke_dir}/demo.msh" --vtu "${smoke_dir}/../smoke/demo.msh" --json)
smoke_test(NAME mesh_quality.svg_over_vtu.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND mesh_quality "${smoke_dir}/demo.msh" --vtu "${smoke_dir}/demo_q.vtu" --svg "${smoke_dir}/demo_q.vtu" --json)
smoke_test(NAME curve_mesh.svg_over_input.json REQUIRES examples_demo_mesh SETUP examples_not_overwritten
           EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/demo_again.msh" --group wall --geometry circle:0,0,0.5
                   --svg "${smoke_dir}/demo.msh" --json)
smoke_test(NAME curve_mesh.svg_over_vtu.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND curve_mesh --demo -o "${smoke_dir}/demo_svg_vtu.msh" --svg "${smoke_dir}/demo_svg_vtu.vtu" --json)
smoke_test(NAME mesh_info.input_kept.json REQUIRES examples_demo_mesh examples_not_overwritten
           KEYS mesh/groups VALUES mesh/dim=2
           COMMAND mesh_info "${smoke_dir}/demo.msh" --json)
smoke_test(NAME curve_mesh.demo_with_input.json EXPECT_RC 1 KEYS error VALUES kind=usage
           COMMAND curve_mesh "${smoke_dir}/demo.msh" --demo -o "${smoke_dir}/demo_and_input.msh" --json)
smoke_test(NAME curve_mesh.cgns_order5_output.json EXPECT_RC 1 KEYS error
           COMMAND curve_mesh --demo --order 5 -o "${smoke_dir}/demo_curved_p5.cgns" --json)
smoke_test(NAME move_mesh.unknown_output.json REQUIRES examples_demo_mesh EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved.cgnx" --group wall --rotate 1 --json)
smoke_test(NAME move_mesh.output_is_input.json EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/clockwise.su2" -o "${smoke_dir}/clockwise.su2" --group bottom
                   --translate 0.01,0 --fixed rest --json)
smoke_test(NAME move_mesh.json_file_name_with_quote.json
           KEYS output VALUES output=${smoke_dir}/moved\"quote.su2
           COMMAND move_mesh "${smoke_dir}/clockwise.su2" -o "${smoke_dir}/moved\"quote.su2" --group bottom
                   --translate 0.01,0 --fixed rest --json)

# CGNS in and out (when built with the CGNS library): a linear CGNS mesh written by move_mesh,
# read by mesh_info and curved by curve_mesh into a curved CGNS mesh; the demo's P2 mesh moved
# into CGNS keeps every cell valid.
if(MESHMOTION_HAVE_CGNS)
  smoke_test(NAME move_mesh.cgns_output.json SETUP examples_square_cgns KEYS output VALUES after/invalid=0
             COMMAND move_mesh "${smoke_dir}/clockwise.su2" -o "${smoke_dir}/square.cgns" --group bottom
                     --translate 0.01,0 --fixed rest --json)
  smoke_test(NAME mesh_info.cgns.json REQUIRES examples_square_cgns KEYS mesh/groups VALUES mesh/nodes=4,mesh/cells/tri3=2
             COMMAND mesh_info "${smoke_dir}/square.cgns" --json)
  smoke_test(NAME curve_mesh.cgns.json REQUIRES examples_square_cgns KEYS output,min_scaled_jacobian VALUES invalid=0
             COMMAND curve_mesh "${smoke_dir}/square.cgns" -o "${smoke_dir}/square_curved.cgns" --group bottom
                     --geometry straight --json)
  smoke_test(NAME move_mesh.demo_to_cgns.json REQUIRES examples_demo_mesh SETUP examples_moved_cgns
             KEYS output VALUES after/invalid=0
             COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_demo.cgns" --group wall --rotate 5
                     --fixed farfield --json)
  smoke_test(NAME mesh_quality.cgns.json REQUIRES examples_moved_cgns VALUES metrics/scaled_jacobian/invalid=0
             KEYS nodes
             COMMAND mesh_quality "${smoke_dir}/moved_demo.cgns" --metric jacobian --json)
endif()

# OpenFOAM cases: a 3D mesh written as a new case (a folder), read back by mesh_info and
# mesh_quality (with checkMesh's measures), moved into a time folder of the case, and the case
# itself refused as output without --overwrite.
file(WRITE "${smoke_dir}/two_hexes.su2" "NDIME= 3\nNELEM= 2\n12 0 1 4 3 6 7 10 9 0\n12 1 2 5 4 7 8 11 10 1\nNPOIN= 12\n"
     "0 0 0 0\n1 0 0 1\n2 0 0 2\n0 1 0 3\n1 1 0 4\n2 1 0 5\n0 0 1 6\n1 0 1 7\n2 0 1 8\n0 1 1 9\n1 1 1 10\n2 1 1 11\n"
     "NMARK= 2\nMARKER_TAG= bottom\nMARKER_ELEMS= 2\n9 0 3 4 1\n9 1 4 5 2\nMARKER_TAG= top\nMARKER_ELEMS= 2\n9 6 7 10 9\n9 7 8 11 10\n")
file(REMOVE_RECURSE "${smoke_dir}/foam_case")
smoke_test(NAME move_mesh.new_openfoam_case.json SETUP examples_foam_case KEYS output VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/two_hexes.su2" -o "${smoke_dir}/foam_case" --group top --translate 0,0,0.1
                   --fixed bottom --json)
smoke_test(NAME mesh_info.openfoam.json REQUIRES examples_foam_case KEYS mesh/groups,openfoam/patches
           VALUES mesh/nodes=12,mesh/cells/hex8=2,openfoam/cells=2,openfoam/faces=11,openfoam/cell_shapes/hexahedra=2,openfoam/cell_shapes/polyhedra=0
           COMMAND mesh_info "${smoke_dir}/foam_case" --json)
smoke_test(NAME mesh_quality.openfoam.json REQUIRES examples_foam_case
           KEYS checkmesh/max_non_orthogonality,checkmesh/max_skewness,checkmesh/max_aspect_ratio
           VALUES checkmesh/solution_directions=3,checkmesh/highly_skewed_faces=0,checkmesh/nonpositive_volume_cells=0,checkmesh/failed_checks=0
           COMMAND mesh_quality "${smoke_dir}/foam_case" --json)
smoke_test(NAME move_mesh.openfoam_time_folder.json REQUIRES examples_foam_case SETUP examples_foam_time KEYS output
           VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/foam_case" -o "${smoke_dir}/foam_case/0.5" --group top --translate 0.05,0,0
                   --fixed bottom --json)
# From that time folder (OpenFOAM's -time 0.5) on, groups named by patterns as OpenFOAM's
# dictionaries name patches; a pattern that names no group is refused.
smoke_test(NAME move_mesh.openfoam_from_time_folder_by_patterns.json REQUIRES examples_foam_time KEYS output
           VALUES after/invalid=0,input=${smoke_dir}/foam_case/0.5
           COMMAND move_mesh "${smoke_dir}/foam_case/0.5" -o "${smoke_dir}/foam_case/0.75" --group "t.p" --translate 0.05,0,0
                   --fixed "(bottom|inlet)" --json)
smoke_test(NAME mesh_info.openfoam_time_option.json REQUIRES examples_foam_time KEYS mesh
           VALUES file=${smoke_dir}/foam_case/0.5
           COMMAND mesh_info "${smoke_dir}/foam_case" --time 0.5 --json)
smoke_test(NAME mesh_info.openfoam_time_option_absent.json REQUIRES examples_foam_time EXPECT_RC 1 KEYS error
           COMMAND mesh_info "${smoke_dir}/foam_case" --time 0.3 --json)
smoke_test(NAME move_mesh.openfoam_pattern_naming_nothing.json REQUIRES examples_foam_case EXPECT_RC 1 KEYS error
           VALUES kind=input
           COMMAND move_mesh "${smoke_dir}/foam_case" -o "${smoke_dir}/foam_case/0.9" --group top --translate 0.05,0,0
                   --fixed "(inlet|outlet)" --json)
smoke_test(NAME move_mesh.openfoam_polymesh_folder_of_input_needs_overwrite.json REQUIRES examples_foam_case EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/foam_case" -o "${smoke_dir}/foam_case/constant/polyMesh" --group top --translate 0.05,0,0 --json)
smoke_test(NAME move_mesh.openfoam_no_case_inside_the_case.json REQUIRES examples_foam_case EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/foam_case" -o "${smoke_dir}/foam_case/latest" --group top --translate 0.05,0,0 --json)
smoke_test(NAME move_mesh.openfoam_in_place_needs_overwrite.json REQUIRES examples_foam_case EXPECT_RC 1 KEYS error
           COMMAND move_mesh "${smoke_dir}/foam_case" -o "${smoke_dir}/foam_case" --group top --translate 0.05,0,0
                   --fixed bottom --json)

# A polyhedral case (a cell with a hanging node beside two hexahedra): moved, it is judged on
# its own cells by checkMesh's measures, not on the tetrahedra the library cuts it into.
set(foam_header "FoamFile { version 2.0; format ascii; class")
file(REMOVE_RECURSE "${smoke_dir}/foam_poly")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/points" "${foam_header} vectorField; object points; }\n16\n("
     "(0 0 0) (1 0 0) (2 0 0) (1 1 0) (2 1 0) (0 2 0) (1 2 0) (2 2 0) (0 0 1) (1 0 1) (2 0 1) (1 1 1) (2 1 1) (0 2 1) (1 2 1) (2 2 1))\n")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/faces" "${foam_header} faceList; object faces; }\n16\n("
     "4(1 3 11 9) 4(3 6 14 11) 4(3 11 12 4) 4(0 8 13 5) 4(2 4 12 10) 4(4 7 15 12) 4(0 1 9 8) 4(1 2 10 9) 4(5 13 14 6) "
     "4(6 14 15 7) 5(0 5 6 3 1) 4(1 3 4 2) 4(3 6 7 4) 5(8 9 11 14 13) 4(9 10 12 11) 4(11 12 15 14))\n")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/owner" "${foam_header} labelList; object owner; }\n16\n(0 0 1 0 1 2 0 1 0 2 0 1 2 0 1 2)\n")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/neighbour" "${foam_header} labelList; object neighbour; }\n3\n(1 2 2)\n")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/boundary" "${foam_header} polyBoundaryMesh; object boundary; }\n4\n("
     "wall { type wall; inGroups List<word> 1(body); nFaces 1; startFace 3; } outlet { type patch; nFaces 2; startFace 4; } "
     "sides { type patch; nFaces 4; startFace 6; } frontAndBack { type empty; nFaces 6; startFace 10; })\n")
file(WRITE "${smoke_dir}/foam_poly/constant/polyMesh/cellZones" "${foam_header} regIOobject; object cellZones; }\n1\n("
     "hexes { type cellZone; cellLabels List<label> 2(1 2); })\n")
smoke_test(NAME move_mesh.openfoam_polyhedra_judged_on_cells.json KEYS output,checkmesh_after/max_skewness
           VALUES after/invalid=0,checkmesh_after/invalid_cells=0,checkmesh_after/failed_checks=0
           COMMAND move_mesh "${smoke_dir}/foam_poly" -o "${smoke_dir}/foam_poly/0.1" --group body --translate 0.05,0,0
                   --fixed "(outlet|sides)" --sliding frontAndBack:0,0,1 --method sle --json)
smoke_test(NAME mesh_info.openfoam_polyhedra.json KEYS openfoam/patches
           VALUES openfoam/cells=3,openfoam/cell_shapes/hexahedra=2,openfoam/cell_shapes/polyhedra=1,mesh/cells/tet4=78,openfoam/zones/0/name=hexes,openfoam/zones/0/kind=cellZone,openfoam/zones/0/size=2
           COMMAND mesh_info "${smoke_dir}/foam_poly" --json)
# Displacements of a polyhedral case's wall by OpenFOAM's point labels: the centre of its face
# (the library's node) follows.
file(WRITE "${smoke_dir}/foam_poly_wall.txt" "0 0.01 0 0\n5 0.01 0 0\n8 0.01 0 0\n13 0.01 0 0\n")
smoke_test(NAME move_mesh.openfoam_polyhedra_displacements_by_label.json KEYS output VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/foam_poly" -o "${smoke_dir}/foam_poly/0.2" --group wall
                   --displacements "${smoke_dir}/foam_poly_wall.txt" --fixed outlet --json)
# move_mesh_mpi takes a case folder as move_mesh does, judges it on its own cells and writes a
# time folder into it: the points move_mesh writes, byte for byte.
if(TARGET move_mesh_mpi)
  set(poly_motion --group body --translate 0.05,0,0 --fixed "(outlet|sides)" --sliding frontAndBack:0,0,1 --json)
  smoke_test(NAME move_mesh_mpi.openfoam_case.json SETUP examples_foam_poly_mpi RANKS 2 KEYS checkmesh_after/max_skewness
             VALUES after/invalid=0,checkmesh_after/invalid_cells=0,ranks=2
             COMMAND move_mesh_mpi "${smoke_dir}/foam_poly" -o "${smoke_dir}/foam_poly/0.5" ${poly_motion})
  smoke_test(NAME move_mesh_mpi.openfoam_case_serial_peer.json SETUP examples_foam_poly_mpi_peer KEYS output
             COMMAND move_mesh "${smoke_dir}/foam_poly" -o "${smoke_dir}/foam_poly/0.6" ${poly_motion})
  add_test(NAME examples.move_mesh_mpi.openfoam_case_equals_move_mesh
           COMMAND "${CMAKE_COMMAND}" -E compare_files "${smoke_dir}/foam_poly/0.5/polyMesh/points"
                   "${smoke_dir}/foam_poly/0.6/polyMesh/points")
  set_tests_properties(examples.move_mesh_mpi.openfoam_case_equals_move_mesh PROPERTIES LABELS examples
                       FIXTURES_REQUIRED "examples_foam_poly_mpi;examples_foam_poly_mpi_peer")
endif()
# A cell zone moved as a body, written as a new case: the case's own cells, patches and zone.
file(REMOVE_RECURSE "${smoke_dir}/foam_poly_moved")
smoke_test(NAME move_mesh.openfoam_zone_to_new_case.json SETUP examples_foam_poly_moved KEYS output
           VALUES after/invalid=0,checkmesh_after/invalid_cells=0
           COMMAND move_mesh "${smoke_dir}/foam_poly" -o "${smoke_dir}/foam_poly_moved" --group hexes --translate 0.05,0,0
                   --fixed wall --method sle --json)
smoke_test(NAME mesh_info.openfoam_new_case_keeps_cells.json REQUIRES examples_foam_poly_moved KEYS openfoam/patches
           VALUES openfoam/cells=3,openfoam/cell_shapes/polyhedra=1,openfoam/patches/0/type=wall,openfoam/patches/3/type=empty,openfoam/zones/0/name=hexes
           COMMAND mesh_info "${smoke_dir}/foam_poly_moved" --json)

# A 2D case stored in 3D: front (y = 0) and back (y = 1) are one group, two parallel planes.
# It slides with the normal given (each node in its own plane); without it no plane fits.
file(WRITE "${smoke_dir}/two_hexes_front_back.su2" "NDIME= 3\nNELEM= 2\n12 0 1 4 3 6 7 10 9 0\n12 1 2 5 4 7 8 11 10 1\n"
     "NPOIN= 12\n0 0 0 0\n1 0 0 1\n2 0 0 2\n0 1 0 3\n1 1 0 4\n2 1 0 5\n0 0 1 6\n1 0 1 7\n2 0 1 8\n0 1 1 9\n1 1 1 10\n"
     "2 1 1 11\nNMARK= 3\nMARKER_TAG= bottom\nMARKER_ELEMS= 2\n9 0 3 4 1\n9 1 4 5 2\nMARKER_TAG= top\nMARKER_ELEMS= 2\n"
     "9 6 7 10 9\n9 7 8 11 10\nMARKER_TAG= frontAndBack\nMARKER_ELEMS= 4\n9 0 1 7 6\n9 1 2 8 7\n9 3 9 10 4\n9 4 10 11 5\n")
smoke_test(NAME move_mesh.sliding_with_normal.json KEYS output VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/two_hexes_front_back.su2" -o "${smoke_dir}/front_back_moved.vtu" --group top
                   --translate 0.05,0,0 --fixed bottom --sliding frontAndBack:0,1,0 --method le --json)
smoke_test(NAME move_mesh.sliding_two_planes_without_normal.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND move_mesh "${smoke_dir}/two_hexes_front_back.su2" -o "${smoke_dir}/front_back_refused.vtu" --group top
                   --translate 0.05,0,0 --fixed bottom --sliding frontAndBack --method le --json)
smoke_test(NAME move_mesh.sliding_normal_of_two_values.json EXPECT_RC 1 KEYS error VALUES kind=input
           COMMAND move_mesh "${smoke_dir}/two_hexes_front_back.su2" -o "${smoke_dir}/front_back_refused.vtu" --group top
                   --translate 0.05,0,0 --fixed bottom --sliding frontAndBack:0,1 --json)

# A 2D case stored in 3D: four hexahedra one cell thick along z, front and back one group.
# It moves as its 2D section (every method keeps front and back alike and in their planes),
# takes a centre X,Y, and the front and back slide without a normal given; --keep-3d and a
# motion along z move it in 3D.
file(WRITE "${smoke_dir}/slab_2d.su2" "NDIME= 3\nNELEM= 4\n12 0 1 4 3 9 10 13 12 0\n12 1 2 5 4 10 11 14 13 1\n12 3 4 7 6 12 13 16 15 2\n12 4 5 8 7 13 14 17 16 3\nNPOIN= 18\n0 0 0 0\n1 0 0 1\n2 0 0 2\n0 1 0 3\n1 1 0 4\n2 1 0 5\n0 2 0 6\n1 2 0 7\n2 2 0 8\n0 0 0.1 9\n1 0 0.1 10\n2 0 0.1 11\n0 1 0.1 12\n1 1 0.1 13\n2 1 0.1 14\n0 2 0.1 15\n1 2 0.1 16\n2 2 0.1 17\nNMARK= 3\nMARKER_TAG= bottom\nMARKER_ELEMS= 2\n9 0 1 10 9\n9 1 2 11 10\nMARKER_TAG= top\nMARKER_ELEMS= 2\n9 7 6 15 16\n9 8 7 16 17\nMARKER_TAG= frontAndBack\nMARKER_ELEMS= 8\n9 0 3 4 1\n9 9 10 13 12\n9 1 4 5 2\n9 10 11 14 13\n9 3 6 7 4\n9 12 13 16 15\n9 4 7 8 5\n9 13 14 17 16\n")
smoke_test(NAME move_mesh.section_2d_elasticity.json KEYS output VALUES section_axis=z,after/invalid=0
           COMMAND move_mesh "${smoke_dir}/slab_2d.su2" -o "${smoke_dir}/slab_2d_le.su2" --group top --rotate 5
                   --center 1,1 --fixed bottom --method le --json)
smoke_test(NAME move_mesh.section_2d_sliding_front_and_back.json KEYS output VALUES section_axis=z,after/invalid=0
           COMMAND move_mesh "${smoke_dir}/slab_2d.su2" -o "${smoke_dir}/slab_2d_dgrbf.su2" --group top --rotate 5
                   --center 1,1 --fixed bottom --sliding frontAndBack --method dgrbf --json)
smoke_test(NAME move_mesh.section_2d_keep_3d.json KEYS output,options VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/slab_2d.su2" -o "${smoke_dir}/slab_2d_3d.su2" --group top --rotate 5
                   --center 1,1,0 --fixed bottom --keep-3d --json)
smoke_test(NAME move_mesh.section_2d_motion_along_axis.json KEYS output VALUES after/invalid=0
           COMMAND move_mesh "${smoke_dir}/slab_2d.su2" -o "${smoke_dir}/slab_2d_z.su2" --group top
                   --translate 0.05,0,0.01 --fixed bottom --json)

# move_mesh_mpi: the same mesh as move_mesh's (to 1e-10) from 3 ranks with the boundary
# system replicated (the serial mover's factorization); through PETSc on request; the
# partition of unity with its patches on the ranks (automatic's choice for it); elasticity
# through PETSc; an unknown group or boundary solve refused by every rank with rank 0's message.
if(TARGET move_mesh_mpi)
  smoke_test(NAME move_mesh_mpi.help KEYS "" EXPECT_RC 0 RANKS 1 COMMAND move_mesh_mpi --version)
  smoke_test(NAME move_mesh_mpi.serial_peer.json REQUIRES examples_demo_mesh SETUP examples_mpi_serial_peer
             KEYS after/min
             COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_serial_peer.msh" --group wall --rotate 5
                     --fixed farfield --json)
  smoke_test(NAME move_mesh_mpi.rbf.json REQUIRES examples_demo_mesh SETUP examples_mpi_moved RANKS 3
             KEYS ranks,threads_per_rank,setup_seconds,move_seconds,after/min,after/histogram,mover_steps
             VALUES ranks=3,threads_per_rank=1,boundary_solve=replicated,method=rbf,steps=1,after/invalid=0,mover_steps/0/factorizations=0
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi.msh" --group wall --rotate 5
                     --fixed farfield --boundary-solve replicated --json)
  # rigid_part=none: the wall's rigid turn would be blended and nothing solved through PETSc.
  smoke_test(NAME move_mesh_mpi.rbf_petsc.json REQUIRES examples_demo_mesh RANKS 2
             KEYS after/min VALUES boundary_solve=petsc,threads_per_rank=2,after/invalid=0,mover_steps/0/factorizations=1
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_petsc.vtu" --group wall --rotate 5
                     --fixed farfield --boundary-solve petsc --threads 2 --rigid-part none --json)
  smoke_test(NAME move_mesh_mpi.rbf_patches.json REQUIRES examples_demo_mesh RANKS 2
             KEYS after/min VALUES boundary_solve=patches,after/invalid=0
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_patches.vtu" --group wall --rotate 5
                     --fixed farfield --partition-of-unity --patch-centres 8 --json)
  smoke_test(NAME move_mesh_mpi.bad_boundary_solve.json REQUIRES examples_demo_mesh RANKS 2 EXPECT_RC 1 KEYS error
             VALUES kind=input
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_bad_solve.msh" --group wall --rotate 5
                     --boundary-solve mumps --json)
  # Both set up at rest and blend the wall's rigid turn: the ranks' sums of the fit differ
  # from the serial one in the last bits, so the points agree to 1e-10, not byte for byte.
  smoke_test(NAME move_mesh_mpi.equals_move_mesh.json REQUIRES examples_mpi_moved examples_mpi_serial_peer
             KEYS compared/relative VALUES compared/within=ON
             COMMAND mesh_info "${smoke_dir}/moved_mpi.msh" --compare "${smoke_dir}/moved_serial_peer.msh" --json)
  # Where the memory budget binds, the distributed mover reaches move_mesh's reduced radius on
  # its own (neither program chooses one): the same mesh, byte for byte. rigid_part=none: a
  # budget-cut radius would have the serial mover blend the wall's rigid turn, which the
  # distributed mover does not (docs/architecture.md).
  smoke_test(NAME move_mesh_mpi.budget_serial_peer.json REQUIRES examples_demo_mesh SETUP examples_mpi_budget_serial
             KEYS support_radius VALUES mover_steps/0/radius_reduced=ON
             COMMAND move_mesh "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_budget_serial.msh" --group wall --rotate 5
                     --fixed farfield --rigid-part none --max-memory-bytes 1e7 --json)
  smoke_test(NAME move_mesh_mpi.budget.json REQUIRES examples_demo_mesh SETUP examples_mpi_budget_moved RANKS 2
             KEYS support_radius VALUES mover_steps/0/radius_reduced=ON,boundary_solve=replicated
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_budget_mpi.msh" --group wall --rotate 5
                     --fixed farfield --rigid-part none --max-memory-bytes 1e7 --boundary-solve replicated --json)
  add_test(NAME examples.move_mesh_mpi.budget_equals_move_mesh
           COMMAND "${CMAKE_COMMAND}" -E compare_files "${smoke_dir}/moved_budget_mpi.msh" "${smoke_dir}/moved_budget_serial.msh")
  set_tests_properties(examples.move_mesh_mpi.budget_equals_move_mesh PROPERTIES LABELS examples
                       FIXTURES_REQUIRED "examples_mpi_budget_moved;examples_mpi_budget_serial")
  smoke_test(NAME move_mesh_mpi.sle.json REQUIRES examples_demo_mesh RANKS 2
             KEYS petsc_solver VALUES method=sle,petsc_solver=cg_hypre,after/invalid=0
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_sle.vtu" --group wall --rotate 2
                     --fixed farfield --method sle --petsc-solver cg_hypre --rank-files --json)
  smoke_test(NAME move_mesh_mpi.p2_to_openfoam.json REQUIRES examples_demo_mesh RANKS 2 EXPECT_RC 1 KEYS error
             VALUES kind=input
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_p2_case" --group wall --rotate 5
                     --fixed farfield --json)
  smoke_test(NAME move_mesh_mpi.unknown_group.json REQUIRES examples_demo_mesh RANKS 2 EXPECT_RC 1 KEYS error
             VALUES kind=input
             COMMAND move_mesh_mpi "${smoke_dir}/demo.msh" -o "${smoke_dir}/moved_mpi_bad.msh" --group nosuch --rotate 5
                     --json)
endif()

# docs/options.md is what the library's option and report descriptions say: regenerate it with
#   build/examples/curve_mesh --options-markdown > docs/options.md
add_test(NAME examples.curve_mesh.options_markdown_matches_docs
         COMMAND "${CMAKE_COMMAND}" -DPROGRAM=$<TARGET_FILE:curve_mesh> -DDOC=${PROJECT_SOURCE_DIR}/docs/options.md
                 -DGENERATED=${CMAKE_CURRENT_BINARY_DIR}/options.md.generated -P "${CMAKE_CURRENT_LIST_DIR}/compare_output.cmake")
set_tests_properties(examples.curve_mesh.options_markdown_matches_docs PROPERTIES LABELS examples)

# CHOLMOD (with OpenBLAS) and CGNS (with HDF5) are loaded by the first run that needs them,
# not at every program's start (core/detail/shared_library.hpp): the programs do not list them.
find_program(MESHMOTION_LDD ldd)
if(MESHMOTION_LDD AND (MESHMOTION_HAVE_CHOLMOD OR MESHMOTION_HAVE_CGNS))
  foreach(program curve_mesh move_mesh)
    add_test(NAME examples.${program}.starts_without_cholmod_or_cgns COMMAND ${MESHMOTION_LDD} $<TARGET_FILE:${program}>)
    set_tests_properties(examples.${program}.starts_without_cholmod_or_cgns PROPERTIES LABELS examples
                         PASS_REGULAR_EXPRESSION "libc\\.so" FAIL_REGULAR_EXPRESSION "libcholmod|libopenblas|libcgns|libhdf5")
  endforeach()
endif()
