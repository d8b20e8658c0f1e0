#include "sid.h"

#include <deque>
#include <map>
#include <set>

namespace caliper::collada::internal {

namespace {

constexpr int kMaxHops = 32;

bool Followed(const Element& e) {
  const std::string_view n = e.local_name();
  return n == "instance_node" || n == "instance_joint" || n == "instance_kinematics_model" ||
         n == "instance_articulated_system" || n == "instance_formula" ||
         n == "instance_kinematics_scene" || n == "instance_physics_model";
}

// Breadth-first search below `from` for an element with this sid; the path to it (from's
// descendants, instance elements followed) goes to `path`.
const Element* FindSid(const Context& ctx, const Element* from, const std::string& sid,
                       std::vector<const Element*>* path) {
  std::deque<const Element*> queue;
  std::map<const Element*, const Element*> came_from;
  std::set<const Element*> seen{from};
  auto expand = [&](const Element* e) {
    for (const auto& c : e->children)
      if (seen.insert(c.get()).second) {
        came_from[c.get()] = e;
        queue.push_back(c.get());
      }
    if (Followed(*e)) {
      const Element* target = ctx.TryResolve(e->Attribute("url"));
      if (target != nullptr && seen.insert(target).second) {
        came_from[target] = e;
        queue.push_back(target);
      }
    }
  };
  expand(from);
  while (!queue.empty()) {
    const Element* e = queue.front();
    queue.pop_front();
    if (e->Attribute("sid") == sid) {
      std::vector<const Element*> reversed;
      for (const Element* k = e; k != from; k = came_from[k]) reversed.push_back(k);
      path->assign(reversed.rbegin(), reversed.rend());
      return e;
    }
    expand(e);
  }
  return nullptr;
}

}  // namespace

const Element* Ancestor(const Element* e, std::string_view name) {
  for (; e != nullptr; e = e->parent)
    if (e->local_name() == name) return e;
  return nullptr;
}

std::vector<const Element*> ResolveSidRef(const Context& ctx, const std::string& ref,
                                          const Element* scope) {
  std::vector<std::string> parts;
  size_t at = 0;
  while (at <= ref.size()) {
    const size_t slash = ref.find('/', at);
    parts.push_back(ref.substr(at, slash == std::string::npos ? std::string::npos : slash - at));
    if (slash == std::string::npos) break;
    at = slash + 1;
  }
  if (parts.empty() || parts[0].empty()) return {};
  const Element* current = parts[0] == "." ? scope : ctx.doc.FindId(parts[0]);
  if (current == nullptr) return {};
  std::vector<const Element*> trail{current};
  for (size_t i = 1; i < parts.size(); ++i) {
    std::vector<const Element*> path;
    const Element* next = FindSid(ctx, current, parts[i], &path);
    if (next == nullptr && i + 1 == parts.size()) {
      // a member selection (rotate.ANGLE, translate(0)) addresses the element itself
      std::string sid = parts[i];
      const size_t paren = sid.find('(');
      if (paren != std::string::npos) sid = sid.substr(0, paren);
      const size_t dot = sid.rfind('.');
      if (dot != std::string::npos) sid = sid.substr(0, dot);
      if (sid != parts[i]) next = FindSid(ctx, current, sid, &path);
    }
    if (next == nullptr) return {};
    trail.insert(trail.end(), path.begin(), path.end());
    current = next;
  }
  return trail;
}

const Element* FindNewParam(const Context& ctx, const std::string& name, const Element* scope) {
  if (scope != nullptr) {
    std::vector<const Element*> path;
    const Element* found = FindSid(ctx, scope, name, &path);
    if (found != nullptr && found->local_name() == "newparam") return found;
  }
  std::vector<const Element*> stack{ctx.doc.root.get()};
  while (!stack.empty()) {
    const Element* e = stack.back();
    stack.pop_back();
    if (e->local_name() == "newparam" && e->Attribute("sid") == name) return e;
    for (auto it = e->children.rbegin(); it != e->children.rend(); ++it) stack.push_back(it->get());
  }
  return nullptr;
}

const Element* FollowParam(const Context& ctx, const Element* start,
                           std::vector<const Element*>* trail) {
  const Element* e = start;
  for (int hop = 0; e != nullptr && hop < kMaxHops; ++hop) {
    trail->push_back(e);
    const Element* sidref = e->Child("SIDREF");
    if (sidref != nullptr) {
      const auto path = ResolveSidRef(ctx, sidref->Trimmed(), e);
      if (path.empty()) return nullptr;
      trail->insert(trail->end(), path.begin(), path.end() - 1);
      e = path.back();
      continue;
    }
    if (Followed(*e) && e->HasAttribute("url")) {
      e = ctx.TryResolve(e->Attribute("url"));
      continue;
    }
    return e;
  }
  return nullptr;
}

}  // namespace caliper::collada::internal
