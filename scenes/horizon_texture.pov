// horizon_texture.pov - a high-frequency texture receding to the horizon.
//
// Isolates texture aliasing: a fine checker and a marble floor stretch to
// the horizon, so the texture's frequency passes the pixel rate halfway up
// the image.  Nothing here is random: one sample per pixel aliases, and
// only more samples per pixel (antialiasing or resolution scaling) remove
// the moire.  A noise-free +Q1 pass aliases the same way.
//
// Quality knobs (Declare=NAME=VALUE):
//   TileSize   size of a checker tile (default 0.25): smaller aliases sooner
#version 3.7;

#ifndef (TileSize) #declare TileSize = 0.25; #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 1.0, -4>
  look_at  <0, 0.2, 4>
  angle 60
}

light_source { <-20, 30, -20>, rgb 1 }

plane {
  y, 0
  texture {
    pigment { checker rgb <0.9, 0.88, 0.82>, rgb <0.12, 0.14, 0.2> scale TileSize }
    finish { diffuse 0.85 ambient 0.05 }
  }
  texture {
    pigment {
      marble turbulence 0.8
      color_map { [0 rgbt <0.6, 0.2, 0.1, 0.6>] [0.5 rgbt <1, 1, 1, 1>] [1 rgbt <0.2, 0.3, 0.6, 0.6>] }
      scale 0.35
    }
    finish { diffuse 0.85 ambient 0.05 }
  }
}

sky_sphere { pigment { gradient y color_map { [0 rgb <0.85, 0.85, 0.9>] [0.3 rgb <0.35, 0.5, 0.8>] } } }
