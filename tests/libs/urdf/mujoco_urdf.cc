#include "mujoco_urdf.h"

#include <mujoco/mujoco.h>
#include <stdlib.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <stdexcept>

namespace caliper::testing {
namespace {

namespace fs = std::filesystem;

// A folder under the system's temporary directory, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "caliper-mujoco-urdf-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a folder " + pattern);
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Where a mesh file name points, as an absolute path MuJoCo can open.
std::string ResolveMesh(const std::string& name, const fs::path& urdf_dir,
                        const std::vector<std::string>& package_dirs, const std::string& urdf) {
  const std::string package = "package://", file = "file://";
  if (name.rfind(package, 0) == 0) {
    const std::string rest = name.substr(package.size());
    for (const std::string& dir : package_dirs) {
      if (fs::exists(fs::path(dir) / rest)) return (fs::path(dir) / rest).string();
    }
    throw std::runtime_error(urdf + ": mesh " + name + " is in none of the package folders");
  }
  if (name.rfind(file, 0) == 0) return name.substr(file.size());
  if (fs::path(name).is_absolute()) return name;
  return (urdf_dir / name).string();
}

// Every <mesh> element below `element`, depth first.
void CollectMeshes(TiXmlElement* element, std::vector<TiXmlElement*>* meshes) {
  for (TiXmlElement* child = element->FirstChildElement(); child;
       child = child->NextSiblingElement()) {
    if (child->ValueStr() == "mesh") meshes->push_back(child);
    CollectMeshes(child, meshes);
  }
}

// Writes the MuJoCo-readable copy of `urdf_path` into `dir` and returns its path.
std::string WriteCopy(const std::string& urdf_path, const std::vector<std::string>& package_dirs,
                      const MujocoCompiler& compiler, const fs::path& dir) {
  TiXmlDocument doc;
  if (!doc.LoadFile(urdf_path)) {
    throw std::runtime_error(urdf_path + ": " + doc.ErrorDesc() + " at line " +
                             std::to_string(doc.ErrorRow()));
  }
  TiXmlElement* robot = doc.RootElement();
  if (!robot || robot->ValueStr() != "robot") {
    throw std::runtime_error(urdf_path + ": the root element is not <robot>");
  }
  if (robot->FirstChildElement("mujoco")) {
    throw std::runtime_error(urdf_path + ": already has a <mujoco> element");
  }
  const fs::path urdf_dir = fs::absolute(urdf_path).parent_path();
  std::vector<TiXmlElement*> meshes;
  CollectMeshes(robot, &meshes);
  for (TiXmlElement* mesh : meshes) {
    const char* name = mesh->Attribute("filename");
    if (!name) throw std::runtime_error(urdf_path + ": a <mesh> without filename");
    mesh->SetAttribute("filename", ResolveMesh(name, urdf_dir, package_dirs, urdf_path));
  }
  TiXmlElement mujoco("mujoco");
  TiXmlElement options("compiler");
  // absolute file names as written above, not their base names
  options.SetAttribute("strippath", "false");
  options.SetAttribute("fusestatic", compiler.fusestatic ? "true" : "false");
  options.SetAttribute("balanceinertia", compiler.balanceinertia ? "true" : "false");
  options.SetAttribute("discardvisual", compiler.discardvisual ? "true" : "false");
  mujoco.InsertEndChild(options);
  robot->InsertEndChild(mujoco);
  const std::string copy = (dir / fs::path(urdf_path).filename()).string();
  if (!doc.SaveFile(copy)) throw std::runtime_error("cannot write " + copy);
  return copy;
}

// mj_loadXML of the copy: the model, or nullptr with MuJoCo's error text in `error`.
mjModel* LoadCopy(const std::string& urdf_path, const std::vector<std::string>& package_dirs,
                  const MujocoCompiler& compiler, std::string* error) {
  TempDir dir;
  const std::string copy = WriteCopy(urdf_path, package_dirs, compiler, dir.path());
  char text[1000] = "";
  mjModel* model = mj_loadXML(copy.c_str(), nullptr, text, sizeof text);
  *error = text;
  return model;
}

// urdfdom's joint type as a URDF file spells it.
std::string JointTypeName(int type) {
  static const std::map<int, std::string> kNames = {
      {urdf::Joint::REVOLUTE, "revolute"},   {urdf::Joint::CONTINUOUS, "continuous"},
      {urdf::Joint::PRISMATIC, "prismatic"}, {urdf::Joint::FIXED, "fixed"},
      {urdf::Joint::FLOATING, "floating"},   {urdf::Joint::PLANAR, "planar"}};
  const auto it = kNames.find(type);
  return it == kNames.end() ? "unknown" : it->second;
}

// The names of `model`'s objects of `type` with ids `first` to `end` - 1.
std::vector<std::string> Names(const mjModel* model, mjtObj type, int first, int end) {
  std::vector<std::string> names;
  for (int i = first; i < end; ++i) names.push_back(mj_id2name(model, type, i));
  return names;
}

}  // namespace

std::vector<UrdfJoint> ReadUrdfJoints(const std::string& urdf_path) {
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(urdf_path);
  if (!model) throw std::runtime_error(urdf_path + ": liburdfdom cannot parse it");
  TiXmlDocument doc;
  if (!doc.LoadFile(urdf_path)) throw std::runtime_error(urdf_path + ": " + doc.ErrorDesc());
  // urdfdom keeps joints in a map: take the file's order from the document
  std::vector<UrdfJoint> joints;
  for (TiXmlElement* e = doc.RootElement()->FirstChildElement("joint"); e;
       e = e->NextSiblingElement("joint")) {
    const urdf::JointConstSharedPtr j = model->getJoint(e->Attribute("name"));
    UrdfJoint joint;
    joint.name = j->name;
    joint.parent = j->parent_link_name;
    joint.child = j->child_link_name;
    joint.type = JointTypeName(j->type);
    if (j->type == urdf::Joint::CONTINUOUS) {
      joint.lower = -M_PI;
      joint.upper = M_PI;
    } else if (j->limits) {
      joint.lower = j->limits->lower;
      joint.upper = j->limits->upper;
    }
    if (j->mimic) {
      joint.mimic = j->mimic->joint_name;
      joint.multiplier = j->mimic->multiplier;
      joint.offset = j->mimic->offset;
    }
    joints.push_back(joint);
  }
  return joints;
}

std::vector<std::map<std::string, double>> RandomConfigurations(
    const std::vector<UrdfJoint>& joints, int count, unsigned seed) {
  std::mt19937 random(seed);
  std::vector<std::map<std::string, double>> result;
  for (int i = 0; i < count; ++i) {
    std::map<std::string, double> q;
    for (const UrdfJoint& j : joints) {
      const bool moves = j.type == "revolute" || j.type == "continuous" || j.type == "prismatic";
      if (moves && j.mimic.empty()) {
        q[j.name] = std::uniform_real_distribution<double>(j.lower, j.upper)(random);
      }
    }
    // a follower may follow a follower: one pass per joint at most
    for (size_t pass = 0; pass < joints.size(); ++pass) {
      bool missing = false;
      for (const UrdfJoint& j : joints) {
        if (j.mimic.empty() || q.count(j.name)) continue;
        auto leader = q.find(j.mimic);
        if (leader == q.end()) {
          missing = true;
        } else {
          q[j.name] = j.multiplier * leader->second + j.offset;
        }
      }
      if (!missing) break;
    }
    result.push_back(q);
  }
  return result;
}

MujocoUrdf::MujocoUrdf(const std::string& urdf_path, const std::vector<std::string>& package_dirs,
                       const MujocoCompiler& compiler) {
  std::string error;
  model_ = LoadCopy(urdf_path, package_dirs, compiler, &error);
  if (!model_) throw std::runtime_error(urdf_path + ": MuJoCo refuses it: " + error);
  data_ = mj_makeData(model_);
}

MujocoUrdf::~MujocoUrdf() {
  if (data_) mj_deleteData(data_);
  if (model_) mj_deleteModel(model_);
}

int MujocoUrdf::body_count() const { return model_->nbody - 1; }

int MujocoUrdf::joint_count() const { return model_->njnt; }

double MujocoUrdf::total_mass() const {
  double mass = 0;
  for (int i = 1; i < model_->nbody; ++i) mass += model_->body_mass[i];
  return mass;
}

// body 0 is MuJoCo's world
std::vector<std::string> MujocoUrdf::body_names() const {
  return Names(model_, mjOBJ_BODY, 1, model_->nbody);
}

std::vector<std::string> MujocoUrdf::joint_names() const {
  return Names(model_, mjOBJ_JOINT, 0, model_->njnt);
}

double MujocoUrdf::body_mass(const std::string& body) const {
  const int id = mj_name2id(model_, mjOBJ_BODY, body.c_str());
  if (id < 0) throw std::out_of_range("MuJoCo has no body " + body);
  return model_->body_mass[id];
}

std::map<std::string, Eigen::Vector3d> MujocoUrdf::BodyPositions(
    const std::map<std::string, double>& joint_positions) {
  mj_resetData(model_, data_);
  for (const auto& [name, value] : joint_positions) {
    const int id = mj_name2id(model_, mjOBJ_JOINT, name.c_str());
    if (id < 0) throw std::out_of_range("MuJoCo has no joint " + name);
    // one qpos value per joint only for hinges and slides (free and ball joints take 7 and 4)
    if (model_->jnt_type[id] != mjJNT_HINGE && model_->jnt_type[id] != mjJNT_SLIDE) {
      throw std::out_of_range("MuJoCo joint " + name + " is not a hinge or a slide");
    }
    data_->qpos[model_->jnt_qposadr[id]] = value;
  }
  mj_kinematics(model_, data_);
  std::map<std::string, Eigen::Vector3d> positions;
  for (int i = 1; i < model_->nbody; ++i) {
    positions[mj_id2name(model_, mjOBJ_BODY, i)] =
        Eigen::Vector3d(data_->xpos[3 * i], data_->xpos[3 * i + 1], data_->xpos[3 * i + 2]);
  }
  return positions;
}

std::string MujocoLoadError(const std::string& urdf_path,
                            const std::vector<std::string>& package_dirs,
                            const MujocoCompiler& compiler) {
  std::string error;
  mjModel* model = LoadCopy(urdf_path, package_dirs, compiler, &error);
  if (!model) return error;
  mj_deleteModel(model);
  return "";
}

}  // namespace caliper::testing
