// legacy_gamma.pov - a scene written the way POV-Ray 3.6 scenes were:
// assumed_gamma 2.2, colours given in that encoding.
//
// Isolates what a gamma other than 1 does to sampling.  POV-Ray computes
// in the gamma's encoding and averages its antialiasing samples there, so
// an antialiased pixel is not the mean of its samples' linear values: at
// high-contrast detail finer than a pixel (a railing's thin dark bars
// against a bright sky, a fine checkerboard floor receding to the horizon)
// antialiasing reads darker than resolution scaling does.  povpress render
// samples such a scene by resolution scaling alone, and the benchmark's
// references are made without antialiasing (scripts/sweep.sh).  76 of
// Debian's 396 example scenes set a gamma other than 1.  Nothing here is
// random.
//
// Quality knobs (Declare=NAME=VALUE):
//   Bars      number of railing bars (default 60)
//   BarWidth  radius of a bar (default 0.012)
#version 3.7;

#ifndef (Bars)     #declare Bars = 60;        #end
#ifndef (BarWidth) #declare BarWidth = 0.012; #end

// the number, not an expression: povpress render and the benchmark read it
global_settings { assumed_gamma 2.2 }

camera {
  location <0, 1.2, -4>
  look_at  <0, 0.9, 0>
  angle 55
}

light_source { <-8, 12, -10>, rgb 1 }

sky_sphere {
  pigment {
    gradient y
    color_map { [0 rgb <0.95, 0.92, 0.85>] [0.4 rgb <0.55, 0.7, 0.95>] }
  }
}

// a checkerboard floor receding to the horizon
plane {
  y, 0
  pigment { checker rgb <0.9, 0.88, 0.8> rgb <0.15, 0.12, 0.1> scale 0.35 }
  finish { diffuse 0.8 ambient 0.15 }
}

// a railing of thin dark bars against the sky, and its top rail
#declare Iron = texture { pigment { rgb 0.08 } finish { diffuse 0.5 specular 0.4 roughness 0.02 ambient 0.1 } }
#declare I = 0;
#while (I < Bars)
  cylinder { <-3 + 6 * I / (Bars - 1), 0, 1.5>, <-3 + 6 * I / (Bars - 1), 1.9, 1.5>, BarWidth texture { Iron } }
  #declare I = I + 1;
#end
cylinder { <-3.1, 1.9, 1.5>, <3.1, 1.9, 1.5>, 0.03 texture { Iron } }

// a polished ball with a small highlight
sphere {
  <0.9, 0.45, -0.4>, 0.45
  pigment { rgb <0.8, 0.2, 0.15> }
  finish { diffuse 0.7 specular 0.9 roughness 0.003 ambient 0.1 }
}
