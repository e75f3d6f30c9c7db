// media.pov - a light shaft through participating media.
//
// Isolates media sampling noise: a spotlight shines through a slatted
// panel into a scattering haze, casting volumetric shafts.  Few media
// samples per interval give a grainy haze; many give a smooth one.
//
// Quality knobs (Declare=NAME=VALUE):
//   MediaIntervals  media intervals (default 1)
//   MediaSamples    samples per interval (default 6; 60+ for a reference)
//   MediaDensity    scattering density (default 0.18)
#version 3.7;

#ifndef (MediaIntervals) #declare MediaIntervals = 1;  #end
#ifndef (MediaSamples)   #declare MediaSamples = 6;    #end
#ifndef (MediaDensity)   #declare MediaDensity = 0.18; #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 1.6, -6>
  look_at  <0, 1.3, 0>
  angle 55
}

light_source {
  <0, 6, 4>, rgb 3
  spotlight point_at <0, 0, -1> radius 14 falloff 22
  media_interaction on
}
light_source { <-5, 3, -8>, rgb 0.15 shadowless media_interaction off }

// the slats
#declare I = 0;
#while (I < 7)
  box { <-3, 4, 0.3 + 0.7 * I>, <3, 4.1, 0.55 + 0.7 * I> pigment { rgb 0.3 } }
  #declare I = I + 1;
#end

plane { y, 0 pigment { rgb <0.6, 0.58, 0.55> } finish { diffuse 0.8 ambient 0 } }
sphere { <0, 0.8, 0>, 0.8 pigment { rgb <0.3, 0.55, 0.85> } finish { diffuse 0.8 ambient 0 } }

// the haze
box {
  <-4, 0, -3>, <4, 3.95, 6>
  hollow
  pigment { rgbt 1 }
  interior {
    media {
      scattering { 1, rgb MediaDensity extinction 0.8 }
      method 3
      intervals MediaIntervals
      samples MediaSamples, MediaSamples
      jitter 1
    }
  }
}

background { rgb 0 }
