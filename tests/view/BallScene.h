// The viewer's tests' scene, written to a file: small, quick, and lit by a map or a constant sky.
#pragma once

#include <fstream>
#include <string>

namespace envgi::test {

// A small scene file for the viewer's tests: a diffuse ball over a floor, lit by the map at
// envmap (or a constant sky when it is empty), path traced to depth 3.
inline void writeBallScene(const std::string& xml, int width, int height, const std::string& envmap) {
  std::string emitter = envmap.empty() ? R"(<emitter type="constant"><rgb name="radiance" value="1"/></emitter>)"
                                       : R"(<emitter type="envmap"><string name="filename" value=")" + envmap +
                                             R"("/></emitter>)";
  std::ofstream(xml) << R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="3"/></integrator>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0, 1, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value=")" +
                            std::to_string(width) + R"("/><integer name="height" value=")" + std::to_string(height) +
                            R"("/></film>
  </sensor>
  )" + emitter + R"(
  <shape type="sphere"><float name="radius" value="1"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.8"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="3"/><translate y="-1"/></transform></shape>
</scene>)";
}

}  // namespace envgi::test
