// smooth_empty.pov - a smooth, nearly empty scene.
//
// The control: a matte floor fading into fog under a gradient sky, lit by
// a shadowless light.  Nothing is random and there is no edge: the horizon
// dissolves in the fog.  After the base pass no pixel needs more samples,
// and an adaptive renderer should spend almost nothing beyond it.
//
// Quality knobs (Declare=NAME=VALUE):
//   FogDistance  distance at which the fog takes 63% of the light (default 12)
#version 3.7;

#ifndef (FogDistance) #declare FogDistance = 12; #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 1.5, -6>
  look_at  <0, 1, 0>
  angle 50
}

light_source { <-5, 8, -6>, rgb 0.9 shadowless }

plane {
  y, 0
  pigment { gradient x color_map { [0 rgb <0.72, 0.66, 0.58>] [1 rgb <0.6, 0.64, 0.7>] } scale 40 translate -20 * x }
  finish { diffuse 0.8 ambient 0.08 }
}

fog { distance FogDistance rgb <0.78, 0.8, 0.86> }

sky_sphere { pigment { gradient y color_map { [0 rgb <0.78, 0.8, 0.86>] [0.6 rgb <0.45, 0.55, 0.8>] } } }
