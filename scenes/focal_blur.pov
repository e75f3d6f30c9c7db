// focal_blur.pov - depth of field from POV-Ray's focal blur.
//
// Isolates focal-blur noise: a row of spheres and a text block recede from
// the camera, which focuses on the middle one, so near and far objects are
// blurred and noisy at low blur sample counts.  POV-Ray's antialiasing does
// not converge under focal blur; more blur samples do.
//
// Quality knobs (Declare=NAME=VALUE):
//   BlurSamples  minimum and maximum focal-blur samples per pixel (default 4;
//                the maximum is 4x the minimum; 64+ for a reference)
//   Aperture     lens aperture (default 0.4): larger is blurrier
//   Confidence   focal-blur confidence (default 0.9)
//   Variance     focal-blur variance (default 1/128)
#version 3.7;

#ifndef (BlurSamples) #declare BlurSamples = 4;       #end
#ifndef (Aperture)    #declare Aperture = 0.4;        #end
#ifndef (Confidence)  #declare Confidence = 0.9;      #end
#ifndef (Variance)    #declare Variance = 1 / 128;    #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 1.2, -6>
  look_at  <0, 0.6, 2>
  angle 45
  aperture Aperture
  blur_samples BlurSamples, 4 * BlurSamples
  confidence Confidence
  variance Variance
  focal_point <0, 0.6, 2>
}

light_source { <-4, 8, -6>, rgb 1 }
light_source { <6, 4, -2>, rgb 0.4 shadowless }

plane {
  y, 0
  pigment { checker rgb <0.8, 0.8, 0.78>, rgb <0.25, 0.27, 0.3> scale 0.8 }
  finish { diffuse 0.8 ambient 0.03 }
}

#declare I = 0;
#while (I < 7)
  sphere {
    <-2.4 + 0.9 * I, 0.45, -2.5 + 1.6 * I>, 0.45
    pigment { rgb <0.9 - 0.1 * I, 0.3 + 0.08 * I, 0.25 + 0.1 * I> }
    finish { diffuse 0.75 specular 0.5 roughness 0.01 ambient 0.03 }
  }
  #declare I = I + 1;
#end

text {
  ttf "timrom.ttf" "povpress" 0.2, 0
  scale 1.2
  translate <-2.6, 1.3, 7>
  pigment { rgb <0.95, 0.8, 0.2> }
  finish { diffuse 0.8 ambient 0.03 }
}

sky_sphere { pigment { gradient y color_map { [0 rgb <0.7, 0.75, 0.85>] [1 rgb <0.3, 0.4, 0.7>] } } }
