// hdr_highlights.pov - very bright highlights in a dark scene.
//
// Isolates high-dynamic-range error: small, very bright light sources are
// seen directly and in polished spheres, and a jittered area light makes
// their reflections flicker from sample to sample, so single samples reach
// values tens of times brighter than their pixel's mean.  Squared-error
// measures are dominated by a handful of such pixels.
//
// Quality knobs (Declare=NAME=VALUE):
//   AreaN       area-light grid size per side (default 2; 16 for a reference)
//   LightPower  brightness of the lamps (default 40)
#version 3.7;

#ifndef (AreaN)      #declare AreaN = 2;       #end
#ifndef (LightPower) #declare LightPower = 40; #end

global_settings { assumed_gamma 1.0 max_trace_level 8 }

camera {
  location <0, 1.4, -5>
  look_at  <0, 0.8, 0>
  angle 50
}

// three small lamps, visible as glowing spheres
#declare Lamp = array[3] { <-2.2, 2.4, 1.5>, <0.3, 2.9, 2.5>, <2.4, 2.1, 1.0> }
#declare LampCol = array[3] { <1, 0.75, 0.45>, <0.6, 0.8, 1>, <1, 0.5, 0.6> }
#declare I = 0;
#while (I < 3)
  light_source {
    Lamp[I], rgb LampCol[I] * LightPower / 10
    area_light <0.3, 0, 0>, <0, 0.3, 0>, AreaN, AreaN
    adaptive 0 jitter circular orient
    fade_distance 1 fade_power 2
    looks_like {
      sphere { 0, 0.06 pigment { rgb LampCol[I] * LightPower } finish { emission 1 diffuse 0 } }
    }
  }
  #declare I = I + 1;
#end

plane { y, 0 pigment { rgb 0.08 } finish { diffuse 0.7 reflection 0.25 specular 0.8 roughness 0.005 } }

#declare Polished = finish { diffuse 0.2 reflection { 0.6 metallic } specular 1 roughness 0.001 }
sphere { <-1.1, 0.55, 0.3>, 0.55 pigment { rgb <0.9, 0.9, 0.95> } finish { Polished } }
sphere { <0.6, 0.4, -0.4>, 0.4 pigment { rgb <0.95, 0.75, 0.4> } finish { Polished } }
sphere { <1.6, 0.7, 1.3>, 0.7 pigment { rgb <0.5, 0.6, 0.9> } finish { Polished } }
torus { 0.45, 0.12 rotate x * 70 translate <-0.2, 0.55, 1.6> pigment { rgb 0.9 } finish { Polished } }

background { rgb <0.005, 0.005, 0.01> }
