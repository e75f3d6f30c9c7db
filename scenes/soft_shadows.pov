// soft_shadows.pov - soft shadows from a jittered area light.
//
// Isolates area-light noise: a sphere, a box and a cylinder on a checked
// floor, lit by one jittered area light, so the penumbrae are noisy at low
// light-grid sizes and smooth at high ones.  Everything else is noise-free.
//
// Quality knobs (set with Declare=NAME=VALUE on the POV-Ray command line):
//   AreaN      area-light grid size per side (default 3; 16+ for a reference)
//   AreaJitter 1 to jitter the area light (default 1), 0 for a regular grid
#version 3.7;

#ifndef (AreaN)      #declare AreaN = 3;      #end
#ifndef (AreaJitter) #declare AreaJitter = 1; #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 2.2, -5.5>
  look_at  <0, 0.6, 0>
  angle 50
}

light_source {
  <3, 6, -2>, rgb 1.1
  area_light <2.5, 0, 0>, <0, 0, 2.5>, AreaN, AreaN
  adaptive 0
  #if (AreaJitter) jitter #end
  circular orient
}
light_source { <-4, 3, -6>, rgb 0.25 shadowless }

plane {
  y, 0
  pigment { checker rgb <0.75, 0.72, 0.65>, rgb <0.45, 0.47, 0.5> scale 1.5 }
  finish { diffuse 0.85 ambient 0.02 }
}

sphere {
  <-1.2, 0.8, 0.3>, 0.8
  pigment { rgb <0.8, 0.25, 0.2> }
  finish { diffuse 0.8 specular 0.4 roughness 0.02 ambient 0.02 }
}

box {
  <-0.45, 0, -0.45>, <0.45, 1.1, 0.45>
  rotate y * 30
  translate <0.9, 0, 0.8>
  pigment { rgb <0.25, 0.5, 0.8> }
  finish { diffuse 0.8 ambient 0.02 }
}

cylinder {
  <0.2, 0, -0.9>, <0.2, 1.6, -0.9>, 0.12
  pigment { rgb <0.9, 0.85, 0.3> }
  finish { diffuse 0.8 ambient 0.02 }
}

sky_sphere { pigment { gradient y color_map { [0 rgb <0.6, 0.7, 0.9>] [1 rgb <0.2, 0.3, 0.6>] } } }
