# Image files for the simulator's recorded-pair camera and the host tools: PGM, and PNG on
# Debian's libpng (and zlib).
stereohash_module(stereohash_image_files
  SOURCES sim/image_files.cpp
  HEADERS sim/image_files.hpp
  PUBLIC stereohash_image stereohash_base
  PRIVATE PNG::PNG stereohash_input_file)

# Printed models from disk (OBJ, MTL and texture images) for the database builder's callers: the
# tools, the tests and the simulated world.
stereohash_module(stereohash_textured_model_files
  SOURCES sim/textured_model_files.cpp
  HEADERS sim/textured_model_files.hpp
  PUBLIC stereohash_textured_model stereohash_base
  PRIVATE stereohash_image_files stereohash_model stereohash_image stereohash_input_file
          stereohash_model_files)

# The simulated world (hal/sim/world): ray caster, renderer, scene generator and the scenes the
# simulator's camera plays. Linked by the simulator backends, the simulator program, the tools
# and the tests; never by the board program.
stereohash_module(stereohash_sim_world
  SOURCES sim/world/ray_caster.cpp sim/world/renderer.cpp sim/world/printed_surface.cpp
          sim/world/scene_generator.cpp sim/world/sim_world.cpp
          sim/world/model_colours.cpp
  HEADERS sim/world/render_scene.hpp sim/world/rng.hpp sim/world/ray_caster.hpp
          sim/world/renderer.hpp sim/world/printed_surface.hpp sim/world/scene_generator.hpp
          sim/world/sim_world.hpp sim/world/model_colours.hpp
  PUBLIC stereohash_hal_camera_sim stereohash_camera stereohash_model stereohash_image
         stereohash_geometry stereohash_base stereohash_textured_model
  PRIVATE stereohash_model_files stereohash_textured_model_files)
