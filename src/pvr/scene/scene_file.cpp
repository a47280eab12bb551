// JSON scene files (docs/scene-format.md): mesh files placed in the world, extra quad lights,
// and the headset rig. Any other path is loaded as a single mesh file, or as a built-in scene.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pvr/scene/scene.h"
#include "pvr/util/error.h"
#include "pvr/util/input_limits.h"
#include "pvr/util/json_number.h"

namespace pvr {
namespace {

// "${NAME}/x" with NAME from the environment: scene files that refer to meshes we may not ship
// (the classic scenes' licences) name their folder by a variable the user sets.
std::string expandEnvironment(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (text.compare(i, 2, "${") == 0) {
      size_t end = text.find('}', i + 2);
      if (end == std::string::npos) throw Error("unterminated ${...} in '" + text + "'");
      std::string name = text.substr(i + 2, end - i - 2);
      const char* value = std::getenv(name.c_str());
      if (!value || !*value) throw Error("the mesh path '" + text + "' needs the environment variable " + name + " (not set)");
      out += value;
      i = end + 1;
    } else {
      out += text[i++];
    }
  }
  return out;
}


using nlohmann::json;

float number(const json& j, const std::string& what) {
  if (!j.is_number()) throw Error(what + " must be a number");
  return jsonNumber<float>(j, what);
}

Vec3 vec3(const json& j, const std::string& what) {
  if (j.is_number()) return Vec3(number(j, what));
  if (!j.is_array() || j.size() != 3) throw Error(what + " must be an array of 3 numbers");
  return {number(j[0], what), number(j[1], what), number(j[2], what)};
}

Fov fovDegrees(const json& j, const std::string& what) {
  if (!j.is_array() || j.size() != 4) throw Error(what + " must be [left, right, up, down] in degrees");
  const float deg = kPi / 180.0f;
  Fov f{number(j[0], what) * deg, number(j[1], what) * deg, number(j[2], what) * deg, number(j[3], what) * deg};
  auto valid = [](float lo, float hi) { return lo < hi && lo > -kPi / 2 && hi < kPi / 2; };
  if (!valid(f.angleLeft, f.angleRight) || !valid(f.angleDown, f.angleUp))
    throw Error(what + " must satisfy -90 < left < right < 90 and -90 < down < up < 90 degrees");
  return f;
}

void checkKeys(const json& j, const std::string& where, std::initializer_list<const char*> known) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool ok = false;
    for (const char* k : known) ok = ok || it.key() == k;
    if (!ok) throw Error("unknown key '" + it.key() + "' in " + where);
  }
}

void applyCamera(const json& cam, StereoRig& rig) {
  if (!cam.is_object()) throw Error("'camera' must be an object");
  checkKeys(cam, "'camera'", {"position", "look_at", "orientation", "ipd", "fov_deg", "fov_left_deg", "fov_right_deg", "eye_size"});
  if (cam.contains("position")) rig.head.position = vec3(cam["position"], "camera.position");
  if (cam.contains("look_at")) {
    Vec3 target = vec3(cam["look_at"], "camera.look_at");
    Vec3 forward = target - rig.head.position;
    if (!(length(forward) > 0) || length(cross(normalize(forward), {0, 1, 0})) < 1e-4f)
      throw Error("camera.look_at must differ from the position and not be straight up or down");
    rig.head.orientation = lookAtOrientation(rig.head.position, target);
  } else if (cam.contains("orientation")) {
    const json& q = cam["orientation"];
    if (!q.is_array() || q.size() != 4) throw Error("camera.orientation must be a quaternion [x, y, z, w]");
    Quat o{number(q[0], "camera.orientation"), number(q[1], "camera.orientation"), number(q[2], "camera.orientation"),
           number(q[3], "camera.orientation")};
    float n = std::sqrt(o.x * o.x + o.y * o.y + o.z * o.z + o.w * o.w);
    if (!(n > 1e-6f)) throw Error("camera.orientation must be a non-zero quaternion");
    rig.head.orientation = {o.x / n, o.y / n, o.z / n, o.w / n};
  }
  if (cam.contains("ipd")) {
    rig.ipd = number(cam["ipd"], "camera.ipd");
    if (rig.ipd < 0 || rig.ipd > 1) throw Error("camera.ipd must be between 0 and 1 (metres)");
  }
  if (cam.contains("fov_deg")) rig.fov[0] = rig.fov[1] = fovDegrees(cam["fov_deg"], "camera.fov_deg");
  if (cam.contains("fov_left_deg")) rig.fov[0] = fovDegrees(cam["fov_left_deg"], "camera.fov_left_deg");
  if (cam.contains("fov_right_deg")) rig.fov[1] = fovDegrees(cam["fov_right_deg"], "camera.fov_right_deg");
  if (cam.contains("eye_size")) {
    const json& s = cam["eye_size"];
    auto pixels = [](const json& n) { return n.is_number_unsigned() && n.get<uint64_t>() <= 65536; };
    if (!s.is_array() || s.size() != 2 || !pixels(s[0]) || !pixels(s[1]))
      throw Error("camera.eye_size must be [width, height] in whole pixels");
    rig.width = int(s[0].get<uint64_t>());
    rig.height = int(s[1].get<uint64_t>());
  }
}

// A sun's or sky's optional aim (`what`: "sun" or "sky"): both keys or neither, a positive radius.
void readAim(const json& light, const std::string& what, Vec3& center, float& radius) {
  if (light.contains("aim_center") != light.contains("aim_radius"))
    throw Error("a " + what + "'s aim needs both aim_center and aim_radius");
  if (!light.contains("aim_center")) return;
  center = vec3(light["aim_center"], what + " aim_center");
  radius = number(light["aim_radius"], what + " aim_radius");
  if (!(radius > 0.0f)) throw Error(what + " aim_radius must be positive");
}

Scene loadJsonScene(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open '" + path + "'");
  std::error_code ec;
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > inputLimits().sceneFileBytes)
    throw Error("scene file '" + path + "' is " + std::to_string(bytes >> 20) + " MiB: at most " +
                std::to_string(inputLimits().sceneFileBytes >> 20) + " MiB");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::parse_error& e) {
    std::string why = e.what();
    throw Error("malformed JSON in '" + path + "': " + why.substr(why.find(']') + 2));
  }
  try {
    if (!doc.is_object()) throw Error("the top level must be an object");
    checkKeys(doc, "the scene file", {"base", "meshes", "lights", "camera", "effects", "effect_groups"});
    auto effectLevel = [](const json& j, const std::string& what) {
      EffectLevel level;
      if (!j.is_string() || !effectLevelFromName(j.get<std::string>(), level))
        throw Error(what + " must be raster, shadows, reflections, gi or path");
      return level;
    };
    Scene scene;
    if (doc.contains("base")) {
      if (!doc["base"].is_string()) throw Error("'base' must name a built-in scene");
      scene = builtinScene(doc["base"].get<std::string>());
    }
    scene.name = std::filesystem::path(path).stem().string();
    std::filesystem::path dir = std::filesystem::path(path).parent_path();
    if (doc.contains("meshes")) {
      if (!doc["meshes"].is_array()) throw Error("'meshes' must be an array");
      for (const json& m : doc["meshes"]) {
        if (!m.is_object() || !m.contains("file") || !m["file"].is_string())
          throw Error("each entry of 'meshes' needs a \"file\"");
        checkKeys(m, "a mesh entry",
                  {"file", "scale", "rotate_deg", "translate", "emission_scale", "import_lights", "effect", "use_camera"});
        ImportOptions opt;
        if (m.contains("import_lights")) {
          if (!m["import_lights"].is_boolean()) throw Error("mesh import_lights must be true or false");
          opt.importLights = m["import_lights"].get<bool>();
        }
        if (m.contains("scale")) opt.scale = vec3(m["scale"], "mesh scale");
        if (m.contains("translate")) opt.translation = vec3(m["translate"], "mesh translate");
        if (m.contains("emission_scale")) opt.emissionScale = number(m["emission_scale"], "mesh emission_scale");
        if (m.contains("rotate_deg")) {  // Euler angles, applied X then Y then Z
          Vec3 r = vec3(m["rotate_deg"], "mesh rotate_deg") * (kPi / 180.0f);
          opt.rotation = Quat::fromAxisAngle({0, 0, 1}, r.z) * Quat::fromAxisAngle({0, 1, 0}, r.y) *
                         Quat::fromAxisAngle({1, 0, 0}, r.x);
        }
        std::filesystem::path file = expandEnvironment(m["file"].get<std::string>());
        const size_t materialsBefore = scene.materials().size();
        const std::string meshPath = (file.is_absolute() ? file : dir / file).string();
        const std::optional<FileCamera> camera = importMeshFile(meshPath, scene, opt);
        if (m.contains("use_camera")) {  // the head where the file's camera is ("camera" below may still move it)
          if (!m["use_camera"].is_boolean()) throw Error("mesh use_camera must be true or false");
          if (m["use_camera"].get<bool>()) {
            if (!camera) throw Error("mesh '" + meshPath + "' has no camera to use (use_camera: a glTF perspective camera)");
            scene.rig.head = camera->pose;
          }
        }
        if (m.contains("effect")) {  // every material this file brought
          const EffectLevel level = effectLevel(m["effect"], "a mesh's \"effect\"");
          for (size_t i = materialsBefore; i < scene.materials().size(); ++i) scene.setEffect(uint32_t(i), level);
        }
      }
    }
    if (doc.contains("lights")) {
      if (!doc["lights"].is_array()) throw Error("'lights' must be an array");
      for (const json& l : doc["lights"]) {
        if (!l.is_object()) throw Error("each light must be an object");
        auto angle = [&](const char* key, float fallback) {
          float deg = l.contains(key) ? number(l[key], std::string("light ") + key) : fallback;
          if (!(deg >= 0.0f && deg <= 90.0f)) throw Error(std::string("light ") + key + " must be in [0, 90] degrees");
          return deg * (kPi / 180.0f);
        };
        if (l.contains("point") || l.contains("spot") || l.contains("sun")) {
          PunctualLight p;
          if (l.contains("point")) {
            checkKeys(l, "a point light", {"point", "intensity"});
            p.kind = PunctualKind::Point;
            p.position = vec3(l["point"], "light point");
          } else if (l.contains("spot")) {
            checkKeys(l, "a spot light", {"spot", "direction", "intensity", "inner_deg", "outer_deg"});
            p.kind = PunctualKind::Spot;
            p.position = vec3(l["spot"], "light spot");
            p.direction = vec3(l.value("direction", json::array({0, -1, 0})), "light direction");
            p.cosInner = std::cos(angle("inner_deg", 0.0f));
            p.cosOuter = std::cos(angle("outer_deg", 45.0f));
          } else {
            checkKeys(l, "a sun", {"sun", "irradiance", "aim_center", "aim_radius"});
            p.kind = PunctualKind::Directional;
            p.direction = vec3(l["sun"], "light sun") * -1.0f;  // the file gives the way to the sun
            readAim(l, "sun", p.position, p.aimRadius);
          }
          const char* amount = p.kind == PunctualKind::Directional ? "irradiance" : "intensity";
          p.intensity = vec3(l.value(amount, json::array({1, 1, 1})), std::string("light ") + amount);
          scene.addPunctualLight(p, l.contains("point") ? "point" : l.contains("spot") ? "spot" : "sun");
          continue;
        }
        if (l.contains("sky")) {
          checkKeys(l, "a sky", {"sky", "aim_center", "aim_radius"});
          SkyLight sky;
          sky.radiance = vec3(l["sky"], "light sky");
          readAim(l, "sky", sky.aimCenter, sky.aimRadius);
          if (scene.sky().present()) throw Error("a scene has at most one sky");
          scene.setSky(sky);
          continue;
        }
        checkKeys(l, "a light", {"quad", "emission"});
        if (!l.contains("quad") || !l["quad"].is_array() || l["quad"].size() != 4)
          throw Error("a light needs \"quad\" (four corners), \"point\", \"spot\", \"sun\" or \"sky\"");
        Material m;
        m.emission = vec3(l.value("emission", json::array({10, 10, 10})), "light emission");
        if (m.emission.x < 0 || m.emission.y < 0 || m.emission.z < 0) throw Error("light emission must not be negative");
        std::vector<Vec3> corners;
        for (const json& c : l["quad"]) corners.push_back(vec3(c, "light quad corner"));
        uint32_t id = scene.addMaterial(m, "light");
        scene.addMesh("quad light", corners, {}, {0, 1, 2, 0, 2, 3}, id);
      }
    }
    if (doc.contains("camera")) applyCamera(doc["camera"], scene.rig);
    if (doc.contains("effects")) {  // by material name: Ray-VR's material groups
      if (!doc["effects"].is_object()) throw Error("'effects' must map material names to effect levels");
      for (const auto& [name, value] : doc["effects"].items()) {
        const EffectLevel level = effectLevel(value, "the effect of material '" + name + "'");
        bool found = false;
        for (size_t i = 0; i < scene.materials().size(); ++i)
          if (scene.materialNames()[i] == name) scene.setEffect(uint32_t(i), level), found = true;
        if (!found) throw Error("'effects' names material '" + name + "', which the scene does not have");
      }
    }
    if (doc.contains("effect_groups")) {  // {"floor": ["sp_00_pod"], ...}: what --effects GROUP=LEVEL and the controller set
      if (!doc["effect_groups"].is_object()) throw Error("'effect_groups' must map group names to lists of material names");
      for (const auto& [group, members] : doc["effect_groups"].items()) {
        if (group.empty() || group == "rest" || group.find_first_of("=,") != std::string::npos)
          throw Error("effect group name '" + group + "' is reserved or holds '=' or ','");
        if (!members.is_array() || members.empty()) throw Error("effect group '" + group + "' must list material names");
        const uint32_t g = scene.addEffectGroup(group);
        for (const json& member : members) {
          if (!member.is_string()) throw Error("effect group '" + group + "' must list material names");
          bool found = false;
          for (size_t i = 0; i < scene.materials().size(); ++i)
            if (scene.materialNames()[i] == member.get<std::string>()) {
              if (scene.materials()[i].effectGroup != 0)
                throw Error("material '" + member.get<std::string>() + "' is in two effect groups");
              scene.setEffectGroup(uint32_t(i), g), found = true;
            }
          if (!found)
            throw Error("effect group '" + group + "' names material '" + member.get<std::string>() + "', which the scene does not have");
        }
      }
    }
    scene.finalize();
    return scene;
  } catch (const Error& e) {
    throw Error("in '" + path + "': " + e.what());
  } catch (const json::exception& e) {
    throw Error("in '" + path + "': " + e.what());
  }
}

}  // namespace

Scene loadScene(const std::string& pathOrBuiltin) {
  for (const std::string& name : builtinSceneNames())
    if (pathOrBuiltin == name) return builtinScene(name);
  std::filesystem::path p(pathOrBuiltin);
  std::error_code ec;
  if (!std::filesystem::exists(p, ec))
    throw Error("cannot open '" + pathOrBuiltin + "': no such file or built-in scene (built-in: cornell, cornell-caustics, cornell-dense)");
  if (p.extension() == ".json") return loadJsonScene(pathOrBuiltin);
  Scene scene;
  scene.name = p.stem().string();
  const std::optional<FileCamera> camera = importMeshFile(pathOrBuiltin, scene);
  if (scene.lightTriangleCount() == 0 && scene.punctualLights().empty() && scene.triangleCount() > 0) {
    // Most asset-store files carry no light: a sun from above and behind the viewer, so that a
    // good file renders (JSON scenes say what lights them).
    PunctualLight sun;
    sun.kind = PunctualKind::Directional;
    sun.direction = normalize(Vec3(-0.3f, -1.0f, -0.5f));
    sun.intensity = Vec3(3.0f);
    scene.addPunctualLight(sun, "default sun");
    std::fprintf(stderr, "photonvr: note: '%s' has no light: lit by a default sun (3 W/m^2 from above)\n", pathOrBuiltin.c_str());
  }
  scene.finalize();
  if (camera) {
    scene.rig.head = camera->pose;
    std::fprintf(stderr, "photonvr: note: '%s' is viewed from its camera '%s'\n", pathOrBuiltin.c_str(), camera->name.c_str());
    return scene;
  }
  // A bare mesh file without a camera: look at it from in front (+Z), far enough to see all of it.
  Bounds3 b = scene.bounds();
  Vec3 center = (b.lower + b.upper) * 0.5f;
  scene.rig.head.position = center + Vec3(0.0f, 0.0f, 0.5f * b.extent().z + 1.2f * maxComponent(b.extent()));
  scene.rig.head.orientation = lookAtOrientation(scene.rig.head.position, center);
  return scene;
}

}  // namespace pvr
