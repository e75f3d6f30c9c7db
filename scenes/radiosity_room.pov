// radiosity_room.pov - a room lit through a window, by radiosity.
//
// Isolates indirect light: sunlight enters through a window and lights the
// room by diffuse interreflection only.  Low radiosity counts give blotchy
// shading; the pretrace also makes region renders inconsistent unless the
// radiosity data is saved on the base pass (+RFO) and loaded (+RFI).
//
// Quality knobs (Declare=NAME=VALUE):
//   RadCount       radiosity rays per sample (default 35; 400+ for a reference)
//   RadErrorBound  radiosity error bound (default 1.8; 0.3 for a reference)
//   RadBounces     recursion limit (default 1)
//
// povpress declares POVPRESS_PASS: 0 on the base pass, which saves the
// radiosity samples (+RFO), and the pass number on region renders, which
// load them (+RFI).  A region render then skips the pretrace (start = end
// = 1 pixel) and computes almost no new samples, so its shading is the
// base pass's, whatever the region's bounds and resolution.
#version 3.7;

#ifndef (POVPRESS_PASS) #declare POVPRESS_PASS = 0; #end

#ifndef (RadCount)      #declare RadCount = 35;       #end
#ifndef (RadErrorBound) #declare RadErrorBound = 1.8; #end
#ifndef (RadBounces)    #declare RadBounces = 1;      #end

global_settings {
  assumed_gamma 1.0
  radiosity {
    #if (POVPRESS_PASS > 0)
      pretrace_start 1
      pretrace_end 1
    #else
      pretrace_start 0.08
      pretrace_end 0.02
    #end
    count RadCount
    error_bound RadErrorBound
    recursion_limit RadBounces
    nearest_count 5
    low_error_factor 0.5
    gray_threshold 0
    brightness 1
  }
}

camera {
  location <-1.6, 1.5, -2.7>
  look_at  <0.4, 1.0, 1>
  angle 70
}

// the sun, outside, shining through the window
light_source { <30, 25, 40>, rgb <3.2, 3.0, 2.6> }

#declare Wall = finish { diffuse 0.8 ambient 0 }

// room 6 x 3 x 6 with a window in the back wall (z = 3)
difference {
  box { <-3.1, -0.1, -3.1>, <3.1, 3.1, 3.1> }
  box { <-3, 0, -3>, <3, 3, 3> }
  box { <-0.6, 0.8, 2.9>, <2.2, 2.5, 3.2> }
  pigment { rgb <0.85, 0.83, 0.78> }
  finish { Wall }
}
plane { y, 0.001 pigment { rgb <0.7, 0.5, 0.32> } finish { Wall } }

box { <-1.8, 0, 0.8>, <-0.6, 0.8, 2.0> pigment { rgb <0.2, 0.45, 0.75> } finish { Wall } }
sphere { <1.0, 0.5, 0.6>, 0.5 pigment { rgb <0.85, 0.25, 0.15> } finish { Wall } }
cylinder { <2.2, 0, -1.5>, <2.2, 1.4, -1.5>, 0.25 pigment { rgb <0.9, 0.85, 0.3> } finish { Wall } }

sky_sphere { pigment { rgb <0.5, 0.65, 0.95> } }
