// thin_geometry.pov - wires, a fence and grass blades thinner than a pixel.
//
// Isolates geometric aliasing: cables, fence wires and blades a fraction of
// a pixel wide appear as broken dotted lines at one sample per pixel.  The
// error sits on isolated pixels along thin structures, which a smoothing
// estimator tends to miss.  Nothing here is random.
//
// Quality knobs (Declare=NAME=VALUE):
//   WireRadius  radius of the fence wires and cables (default 0.006)
//   Blades      number of grass blades (default 500)
#version 3.7;

#ifndef (WireRadius) #declare WireRadius = 0.006; #end
#ifndef (Blades)     #declare Blades = 500;       #end

global_settings { assumed_gamma 1.0 }

camera {
  location <0, 1.3, -5>
  look_at  <0, 1.1, 0>
  angle 55
}

light_source { <-6, 10, -8>, rgb 1 }
light_source { <5, 4, -6>, rgb 0.3 shadowless }

plane { y, 0 pigment { rgb <0.35, 0.45, 0.25> } finish { diffuse 0.8 ambient 0.05 } }

// fence posts and wires
#declare Metal = texture { pigment { rgb 0.25 } finish { diffuse 0.6 specular 0.6 roughness 0.01 ambient 0.05 } }
#declare I = 0;
#while (I < 5)
  cylinder { <-4 + 2 * I, 0, 1>, <-4 + 2 * I, 1.6, 1>, 0.05 texture { Metal } }
  #declare I = I + 1;
#end
#declare J = 0;
#while (J < 8)
  cylinder { <-4.5, 0.2 + 0.18 * J, 1>, <4.5, 0.2 + 0.18 * J, 1>, WireRadius texture { Metal } }
  #declare J = J + 1;
#end

// overhead cables sagging between two poles
cylinder { <-3.5, 0, 3>, <-3.5, 3.4, 3>, 0.06 texture { Metal } }
cylinder { <3.5, 0, 3>, <3.5, 3.4, 3>, 0.06 texture { Metal } }
#declare K = 0;
#while (K < 3)
  #declare S = 0;
  #while (S < 20)
    #declare X0 = -3.5 + 0.35 * S;
    #declare X1 = X0 + 0.35;
    #declare Y0 = 3.2 - 0.25 * K - 0.4 * (1 - pow(X0 / 3.5, 2));
    #declare Y1 = 3.2 - 0.25 * K - 0.4 * (1 - pow(X1 / 3.5, 2));
    cylinder { <X0, Y0, 3>, <X1, Y1, 3>, WireRadius * 1.5 pigment { rgb 0.05 } }
    sphere { <X1, Y1, 3>, WireRadius * 1.5 pigment { rgb 0.05 } }
    #declare S = S + 1;
  #end
  #declare K = K + 1;
#end

// grass blades in front of the fence
#declare R = seed(7);
#declare B = 0;
#while (B < Blades)
  #declare P = <-4 + 8 * rand(R), 0, -1.5 + 2.3 * rand(R)>;
  #declare H = 0.15 + 0.35 * rand(R);
  cone { P, 0.008, P + <0.15 * (rand(R) - 0.5), H, 0.1 * (rand(R) - 0.5)>, 0.0
         pigment { rgb <0.25 + 0.2 * rand(R), 0.55 + 0.2 * rand(R), 0.15> }
         finish { diffuse 0.8 ambient 0.05 } }
  #declare B = B + 1;
#end

sky_sphere { pigment { gradient y color_map { [0 rgb <0.85, 0.9, 0.95>] [0.4 rgb <0.4, 0.55, 0.85>] } } }
