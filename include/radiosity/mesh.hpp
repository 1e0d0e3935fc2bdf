// The patch hierarchy: polygons meshed into patches, each patch the root of a quadtree of
// elements. Transport is computed from elements (leaves) to patches; radiosity is constant per
// element and interpolated to shared vertices for display, across the edges of a smooth surface.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "radiosity/common.hpp"
#include "radiosity/scene.hpp"

namespace radiosity {
inline namespace v1 {

/// How finely polygons are meshed, and which of them share vertices. Areas are in scene units
/// squared; 0 means "derive from the scene": max_patch_area = total area / 512 and
/// max_element_area = max_patch_area / 4, which gives the default Cornell box a few hundred
/// patches and a few thousand elements. A derived max_patch_area is raised to an explicit
/// max_element_area that exceeds it.
struct MeshOptions {
  float max_patch_area = 0.0f;
  float max_element_area = 0.0f;
  /// Two triangles or quads that share an edge (the same two end points, bit for bit, in either
  /// direction) share its vertices when they have the same material and group and their normals
  /// are at most this many degrees apart, so vertex_values() is continuous across the triangles
  /// of a smooth surface (a tessellated sphere, a host's indexed mesh) and broken at creases and
  /// material changes. In [0, 180); 0 shares nothing between polygons. It changes only the
  /// vertices, never patches or elements, so solves do not depend on it (adaptive subdivision
  /// aside, which reads vertex values).
  float crease_angle_deg = 30.0f;
  /// Cut each polygon along the lines where another polygon divides it: stands on it or passes
  /// through it from border to border (a partition between two rooms that share one floor
  /// polygon, one ceiling, one side wall), so that no element and no interpolated vertex spans
  /// the line: the lit room's light would otherwise show in the dark room. A cut polygon is
  /// meshed as convex pieces (up to 64 lines each), which share vertices (as crease_angle_deg
  /// says) with each other and with the neighbours whose edges they share whole, except along
  /// the contacts themselves.
  /// Contacts that end inside a polygon join into chains: a chain whose loose ends all lie on
  /// the polygon's border, at least a quarter of its diameter long, divides it too (a wall
  /// exported as facets, each foot ending inside the ground triangle it stands on; a
  /// building's corner inside one), and the polygon is cut along each of its contacts' whole
  /// lines, so that no element is left partly under the building. A closed chain or one that ends inside (a block standing on a floor, a wall
  /// that stops in the middle of a room) cuts nothing: rays and hemicubes find what it hides
  /// (grade_at_contacts refines the elements around it).
  /// Neither do lines along a polygon's border (T-junctions, walls meeting at a corner) nor
  /// coplanar neighbours. false meshes every polygon whole.
  bool split_at_contacts = true;
  /// Grade a polygon's elements toward what stands on it or passes through it when its
  /// elements are larger than that object (a house on a large plot, a chair on a coarse floor):
  /// elements at the contact are split until they are a quarter of the object's size, and
  /// around it until they are at most half their distance from it, so the contact's shadow
  /// and darkening show and the mesh coarsens smoothly away from it. The object's extent is
  /// its group's (the polygon's own when both are in one group); the elements are sized by
  /// its height off the polygon's plane within [extent / 4, extent] (a 3 m high house's
  /// shadow is about 3 m across; a coaster is not worth elements of its thickness), and
  /// something larger than the elements (a rug, a picture frame) changes nothing. At most 8
  /// levels below a polygon's elements, and at most twice as many new elements as the mesh
  /// had (at least 32768); what stays coarser then is reported (contact_grading()) and what
  /// `radiosity check` warns about. false: elements as max_element_area alone gives them.
  bool grade_at_contacts = true;
};

/// What MeshOptions::grade_at_contacts did (PatchHierarchy::contact_grading()).
struct ContactGrading {
  std::size_t polygons = 0;      ///< polygons whose elements were graded toward a contact
  std::size_t added_leaves = 0;  ///< leaf elements the grading added
  bool budget_reached = false;   ///< it stopped at its element budget: some contacts stayed coarser
  /// A contact whose elements the grading's limits (8 levels, the budget) left larger than
  /// the object: its shadow and contact cannot show there.
  struct Coarse {
    PolygonId polygon = 0;  ///< the polygon stood on or passed through
    PolygonId other = 0;    ///< a polygon of what stands there (the first found of its group)
    float element = 0.0f;   ///< the largest leaf touching the contact, across (the root of its area)
    float object = 0.0f;    ///< the object's extent (its group's; the polygon's own in one group)
  };
  /// One per polygon and group standing on it, by polygon, then group.
  std::vector<Coarse> coarse;
};

/// A node of a patch's quadtree. Leaves carry the radiosity unknowns; an inner node's value is
/// the area-weighted mean of its children. Triangles split into four similar triangles, quads
/// into four quads through edge midpoints and the centre.
struct Element {
  std::array<std::uint32_t, 4> corners{kNone, kNone, kNone, kNone};  ///< vertex ids, CCW; [3] == kNone for triangles
  std::uint32_t patch = kNone;
  std::uint32_t parent = kNone;       ///< kNone for a patch's root element
  std::uint32_t first_child = kNone;  ///< children are first_child .. first_child + 3; kNone for a leaf
  glm::vec3 centroid{0.0f};
  float area = 0.0f;
  std::uint8_t depth = 0;             ///< 0 for a root

  bool is_leaf() const { return first_child == kNone; }
  int corner_count() const { return corners[3] == kNone ? 3 : 4; }
};

/// A patch: the unit that shoots and receives energy in transport (the "j" of F_ij).
struct Patch {
  PolygonId polygon = 0;
  MaterialId material = 0;
  GroupId group = 0;
  glm::vec3 normal{0.0f};
  glm::vec3 centroid{0.0f};
  float area = 0.0f;
  std::uint32_t root = kNone;  ///< its root element
};

/// Patches, their element quadtrees and the vertices the elements share. Vertices are shared
/// between neighbouring elements of one polygon (including across patch borders) and between
/// smooth neighbouring polygons (MeshOptions::crease_angle_deg), so interpolation blends across
/// the edges of a smooth surface but never across a crease or a material change. Polygons with
/// more than four corners share nothing (their fan triangles do not share either).
/// Thread safety: const member functions may be called concurrently; subdivide() needs exclusive access.
class RADIOSITY_API PatchHierarchy {
 public:
  PatchHierarchy();
  ~PatchHierarchy();
  PatchHierarchy(const PatchHierarchy& other);
  PatchHierarchy& operator=(const PatchHierarchy& other);
  PatchHierarchy(PatchHierarchy&&) noexcept;
  PatchHierarchy& operator=(PatchHierarchy&&) noexcept;
  /// Meshes every polygon of `scene`. Throws Error{invalid_argument} if an area option is
  /// negative or NaN, if max_element_area > max_patch_area, or if crease_angle_deg is outside
  /// [0, 180).
  PatchHierarchy(const Scene& scene, const MeshOptions& options);
  /// The same, reporting Phase::meshing through `on_progress` (at the start, about every 50 ms
  /// and at the end, on the calling thread). When the callback returns false meshing stops
  /// within about that interval and the hierarchy is left empty (no patches).
  PatchHierarchy(const Scene& scene, const MeshOptions& options, const ProgressFn& on_progress);

  const std::vector<Patch>& patches() const { return patches_; }
  /// Every node of every quadtree, inner nodes included; index = element id.
  const std::vector<Element>& elements() const { return elements_; }
  const Element& element(std::uint32_t id) const { return elements_[id]; }
  /// Ids of the leaf elements, in a deterministic order (the radiosity unknowns).
  const std::vector<std::uint32_t>& leaves() const { return leaves_; }
  /// Position of a leaf element in leaves() (its unknown's index), or kNone for an inner node or
  /// an id out of range.
  std::uint32_t leaf_index(std::uint32_t element) const {
    return element < leaf_slot_.size() ? leaf_slot_[element] : kNone;
  }
  const std::vector<glm::vec3>& vertices() const { return vertices_; }
  /// The effective options (derived values filled in).
  const MeshOptions& options() const { return options_; }
  /// What the grading toward contacts did (all zero when it was off or found nothing to do).
  const ContactGrading& contact_grading() const { return grading_; }
  const glm::vec3& normal(std::uint32_t element) const { return patches_[elements_[element].patch].normal; }

  /// Splits a leaf into four children and returns the id of the first. The children reuse
  /// midpoints that a neighbour already created, so vertices stay shared. Throws
  /// Error{invalid_argument} if `element` is not a leaf.
  std::uint32_t subdivide(std::uint32_t element);

  /// Point on an element for (u, v) in [0,1]^2, uniformly distributed over its area when (u, v)
  /// is uniform. A quad's point is its bilinear map at (s, t), with (u, v) warped through the
  /// inverse CDFs of the map's Jacobian (the marginal in s, then the conditional in t), so
  /// stratified (u, v) stay stratified on the quad.
  glm::vec3 sample_point(std::uint32_t element, glm::vec2 uv) const;

  /// Per-vertex values for smooth display from per-element values (indexed by element id; only
  /// leaves are read): the area-weighted mean of the leaves around each vertex (over every
  /// polygon that shares it), then every hanging (T-) vertex set to the linear interpolation
  /// along the coarser neighbour's edge, so the interpolated field is continuous within a
  /// polygon and across the edges it shares with smooth neighbours. Where two smooth
  /// neighbours cut their edge into different numbers of patches (so its inner points are not
  /// shared), the points both sides have are averaged over both and the others interpolated
  /// between them, which keeps the field continuous there too.
  ///
  /// `exposure` (empty, or one value in [0, 1] per element id: Solution::exposure()) is the
  /// share of each leaf that is not buried under a solid standing on it; each leaf then weighs
  /// its area x exposure, since its value is its open part's: a wholly buried leaf (the floor
  /// under a block) does not darken the vertices it shares with open ones, which would
  /// otherwise show as dark wedges along every contact. A vertex with no open leaf around it
  /// takes the mean of its leaves' corners that have one, ring by ring inward (as lightmap
  /// bakers dilate texels under geometry), so the corner of a host triangle that lies under a
  /// block carries its open part's light rather than 0.
  std::vector<Rgb> vertex_values(const std::vector<Rgb>& element_values,
                                 const std::vector<float>& exposure = {}) const;

  /// Fills inner nodes with the area-weighted mean of their children (leaves are read).
  void aggregate(std::vector<Rgb>& element_values) const;

 private:
  /// Both constructors' work; false when `on_progress` (may be null) cancelled.
  bool build(const Scene& scene, const MeshOptions& options, const ProgressFn* on_progress);
  std::uint32_t add_element(const Element& e);
  std::uint32_t add_vertex(const glm::vec3& position, std::uint32_t edge_a, std::uint32_t edge_b);
  std::uint32_t midpoint(std::uint32_t a, std::uint32_t b);
  void add_patch(PolygonId polygon_id, const Polygon& polygon, const std::array<std::uint32_t, 4>& corners);
  /// Meshing's view of which polygon corners and edges are shared (patch_hierarchy.cpp).
  struct Weld;
  /// Mesh polygon `polygon_id` (or a piece of it: `polygon` is then the piece, with the
  /// polygon's material, group and normal); `weld_id` is its id in `weld` (the polygon's own, or
  /// the piece's).
  void mesh_quad(PolygonId polygon_id, const Polygon& polygon, Weld& weld, std::uint32_t weld_id);
  void mesh_triangle(PolygonId polygon_id, const Polygon& polygon, const glm::vec3& p0, const glm::vec3& p1,
                     const glm::vec3& p2, Weld& weld, std::uint32_t weld_id);
  /// Vertex ids for a welded polygon's lattice points (see patch_hierarchy.cpp).
  void place_lattice(std::uint32_t weld_id, const std::vector<glm::vec3>& positions, Weld& weld,
                     std::vector<std::uint32_t>& ids);

  MeshOptions options_;
  ContactGrading grading_;
  std::vector<Patch> patches_;
  std::vector<Element> elements_;
  std::vector<std::uint32_t> leaves_;
  std::vector<std::uint32_t> leaf_slot_;  ///< element id -> index in leaves_ (kNone if inner)
  std::vector<glm::vec3> vertices_;
  /// Which edge each midpoint vertex splits and the midpoint of each split edge: subdivision's
  /// bookkeeping, private to patch_hierarchy.cpp (so its containers are no part of the ABI).
  /// Null only in a moved-from hierarchy.
  struct Edges;
  std::unique_ptr<Edges> edges_;
};

}  // namespace v1
}  // namespace radiosity
