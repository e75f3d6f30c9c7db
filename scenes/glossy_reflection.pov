// glossy_reflection.pov - blurred (glossy) reflection.
//
// Isolates the noise of blurred reflections: a brushed-metal floor and a
// glossy sphere reflect coloured columns.  POV-Ray has no glossy BRDF; a
// blurred reflection is an average of textures whose normals are jittered
// by sub-pixel bumps.  Every texture is traced and averaged for each ray,
// so a few give a noisy reflection and many a smooth one, at a cost that
// grows with their number.
//
// Quality knobs (Declare=NAME=VALUE):
//   BlurTextures  textures averaged per glossy surface (default 3; 64+ for a
//                 reference)
//   Roughness     size of the normal jitter (default 0.35)
#version 3.7;

#ifndef (BlurTextures) #declare BlurTextures = 3;   #end
#ifndef (Roughness)    #declare Roughness = 0.35;   #end

global_settings { assumed_gamma 1.0 max_trace_level 6 }

camera {
  location <0, 1.8, -5.5>
  look_at  <0, 0.8, 0>
  angle 50
}

light_source { <-3, 6, -4>, rgb 1 }
light_source { <4, 3, -5>, rgb 0.35 shadowless }

// A glossy texture: BlurTextures copies of a reflective finish, each with
// its own bump pattern, averaged.
#macro Glossy(Colour, Refl)
  texture {
    average
    texture_map {
      #declare K = 0;
      #while (K < BlurTextures)
        [1 pigment { rgb Colour }
           normal { bumps Roughness translate <K * 7.1, K * 3.3, K * 5.7> scale 0.0008 }
           finish { diffuse 0.3 ambient 0.02 reflection { Refl } specular 0.3 roughness 0.02 }]
        #declare K = K + 1;
      #end
    }
  }
#end

plane { y, 0 Glossy(<0.55, 0.56, 0.6>, 0.55) }

sphere { <0, 0.9, 0.6>, 0.9 Glossy(<0.8, 0.6, 0.35>, 0.6) }

#declare Cols = array[5] { <0.9, 0.2, 0.15>, <0.2, 0.75, 0.25>, <0.2, 0.35, 0.9>,
                           <0.95, 0.85, 0.2>, <0.85, 0.3, 0.8> }
#declare I = 0;
#while (I < 5)
  cylinder {
    <-3 + 1.5 * I, 0, 3>, <-3 + 1.5 * I, 2.6, 3>, 0.3
    pigment { rgb Cols[I] }
    finish { diffuse 0.8 ambient 0.05 }
  }
  #declare I = I + 1;
#end

box { <-6, 0, 4>, <6, 4, 4.2> pigment { rgb 0.85 } finish { diffuse 0.8 ambient 0.05 } }
