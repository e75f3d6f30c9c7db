// still_life.pov - opaque objects on a table under two small area lights.
//
// Isolates the error of an ordinary scene: silhouettes, shadow edges and
// the seams between flat colours, with little noise anywhere else.  At one
// sample per pixel its error sits along those edges, a few percent of the
// pixels, where POV-Ray's own adaptive antialiasing (+AM2) is at its best:
// it subdivides only where neighbouring samples differ.  The area lights'
// penumbrae are narrow and their sampling adaptive, so they add little
// noise.
//
// Quality knobs (Declare=NAME=VALUE):
//   AreaN      area light samples per side (default 4)
#version 3.7;

#ifndef (AreaN)  #declare AreaN = 4;  #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0.4, 2.1, -4.6>
  look_at  <0, 0.55, 0>
  angle 48
}

light_source {
  <-4, 6, -3>, rgb 0.9
  area_light <0.4, 0, 0>, <0, 0, 0.4>, AreaN, AreaN
  adaptive 1
  circular orient
}
light_source { <3, 3, -5>, rgb 0.25 shadowless }

sky_sphere { pigment { gradient y color_map { [0 rgb <0.75, 0.8, 0.9>] [1 rgb <0.35, 0.45, 0.7>] } } }

// the table top and the wall behind, flat colours
plane { y, 0 pigment { rgb <0.55, 0.2, 0.15> } finish { diffuse 0.85 ambient 0.04 } }
plane { z, 3 pigment { rgb <0.6, 0.65, 0.55> } finish { diffuse 0.8 ambient 0.04 } }

#declare Matte = finish { diffuse 0.85 ambient 0.04 }
#declare Glaze = finish { diffuse 0.7 ambient 0.04 specular 0.35 roughness 0.02 }

// a jug, a bowl with fruit, a box and a bottle
union {
  cylinder { <0, 0, 0>, <0, 1.05, 0>, 0.34 }
  torus { 0.34, 0.035 translate y * 1.05 }
  torus { 0.22, 0.045 rotate x * 90 translate <0.38, 0.62, 0> }
  pigment { rgb <0.2, 0.35, 0.65> } finish { Glaze }
  translate <-1.05, 0, 0.55>
}
difference {
  sphere { 0, 0.5 scale <1, 0.55, 1> }
  sphere { 0, 0.46 scale <1, 0.55, 1> translate y * 0.04 }
  plane { y, 0.06 inverse }
  pigment { rgb <0.9, 0.88, 0.8> } finish { Glaze }
  translate <0.25, 0.27, -0.35>
}
sphere { <0.12, 0.38, -0.4>, 0.17 pigment { rgb <0.85, 0.12, 0.08> } finish { Glaze } }
sphere { <0.42, 0.36, -0.28>, 0.15 pigment { rgb <0.95, 0.7, 0.1> } finish { Glaze } }
sphere { <0.28, 0.5, -0.5>, 0.13 pigment { rgb <0.3, 0.6, 0.15> } finish { Glaze } }
box {
  <-0.35, 0, -0.25>, <0.35, 0.4, 0.25>
  pigment { rgb <0.65, 0.45, 0.25> } finish { Matte }
  rotate y * 25 translate <1.35, 0, 0.6>
}
union {
  cylinder { <0, 0, 0>, <0, 0.85, 0>, 0.16 }
  cone { <0, 0.85, 0>, 0.16, <0, 1.15, 0>, 0.05 }
  cylinder { <0, 1.15, 0>, <0, 1.35, 0>, 0.05 }
  pigment { rgb <0.1, 0.4, 0.2> } finish { Glaze }
  translate <0.85, 0, 1.2>
}
