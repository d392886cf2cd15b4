#pragma once
// The built-in demo: a lit, textured cube on a textured checker plane that runs to the horizon —
// the far checks shrink below a pixel (mip-mapping and anisotropic filtering at work) and the
// cube's silhouette shows what antialiasing does. Both textures are procedural (sRGB 8-bit).
#include <memory>
#include <vector>

#include "mipraster/pipeline/draw.hpp"
#include "mipraster/scene/camera.hpp"

namespace mipraster {

struct DemoScene {
    std::vector<std::shared_ptr<Mesh>> meshes;  ///< owned here; draws point into them
    std::vector<Draw> draws;
    Camera camera;          ///< look_at_perspective(eye, target, +y, fovy, aspect, near)
    glm::dvec3 eye, target;
    double fovy = 0.0;      ///< vertical field of view, radians
    double near = 0.0;
    glm::vec4 clear_color;  ///< sky colour, linear premultiplied
};

/// Builds the demo for an image of the given aspect ratio (width / height).
DemoScene make_demo_scene(double aspect);

}  // namespace mipraster
