// The compiled MJCF model (MujocoModel): loading, its digest and its names.
#include <fmt/format.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <mutex>

#include "pegasus/core/error.hpp"
#include "pegasus/io/sha256.hpp"
#include "pegasus/mujoco/mujoco_task.hpp"

namespace pegasus {

namespace {

// MuJoCo reports instability through mjData's warning counters, which the rollout reads and turns into a
// crash; its default handler would also print every warning to stdout.
void silent_warning(const char*) {}

}  // namespace

MujocoModel MujocoModel::load(const std::filesystem::path& path) {
  static std::once_flag silence;
  std::call_once(silence, [] { mju_user_warning = silent_warning; });
  if (!std::filesystem::is_regular_file(path))
    throw InputError(fmt::format("{}: no such MJCF file", path.string()));
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.string().c_str(), nullptr, error, sizeof error);
  if (!m) {
    std::string message = error;
    for (char& c : message)
      if (c == '\n') c = ' ';
    throw InputError(fmt::format("{}: not a valid MJCF model: {}", path.string(), message));
  }
  // A step of zero, negative or NaN seconds would integrate nothing, backwards or into NaN; MuJoCo's compiler
  // takes any of them.
  if (const double h = m->opt.timestep; !(h > 0.0) || !std::isfinite(h)) {
    mj_deleteModel(m);
    throw InputError(fmt::format("{}: option.timestep: expected a positive finite number of seconds, got {}",
                                 path.string(), h));
  }
  MujocoModel out;
  out.model_ =
      std::shared_ptr<const mjModel>(m, [](const mjModel* p) { mj_deleteModel(const_cast<mjModel*>(p)); });
  out.path_ = path;
  return out;
}

std::string MujocoModel::digest() const {
  std::string bytes(static_cast<std::size_t>(mj_sizeModel(get())), '\0');
  mj_saveModel(get(), nullptr, bytes.data(), static_cast<int>(bytes.size()));
  return sha256_hex(bytes);
}

int MujocoModel::id_of(int type, const std::string& name) const {
  return mj_name2id(get(), type, name.c_str());
}

std::string MujocoModel::name_of(int type, int id) const {
  const char* name = mj_id2name(get(), type, id);
  return name ? name : "";
}

}  // namespace pegasus
