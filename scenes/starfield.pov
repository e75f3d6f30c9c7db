// starfield.pov - a night sky of stars smaller than a pixel, and a mirror.
//
// Isolates sub-pixel bright points: 250 small emissive spheres, each a
// fraction of a pixel across and up to 30 times brighter than white, over a
// black sky, with a polished sphere that reflects some of them.  One sample
// per pixel hits a star or misses it entirely, so the error sits in a few
// hundred pixels and a pixel whose samples all missed its star looks
// perfectly smooth.  Nothing here is random.
//
// Quality knobs (Declare=NAME=VALUE):
//   Stars       number of stars (default 250)
//   StarSize    the stars' radius, world units (default 0.012 to 0.032;
//               a pixel is about 0.1 at their distance at 160x120)
#version 3.7;

#ifndef (Stars)    #declare Stars = 250;     #end
#ifndef (StarSize) #declare StarSize = 0.012; #end

global_settings { assumed_gamma 1.0 }

camera { location <0, 1, -6> look_at <0, 1, 0> angle 55 }

light_source { <-3, 5, -4>, rgb 0.6 }

#declare S = seed(7);
#declare I = 0;
#while (I < Stars)
  sphere {
    <rand(S) * 16 - 8, rand(S) * 8 + 0.5, 10 + rand(S) * 10>, StarSize + 0.02 * rand(S)
    pigment { rgb 1 }
    finish { emission 30 * rand(S) diffuse 0 }
    no_shadow
  }
  #declare I = I + 1;
#end

sphere {
  <0, 1, 0>, 1
  pigment { rgb 0.8 }
  finish { diffuse 0.1 reflection 0.8 specular 1 roughness 0.001 }
}

plane { y, 0 pigment { checker rgb 0.05, rgb 0.1 } finish { diffuse 0.6 } }

background { rgb 0 }
