/* plume: constrained Delaunay triangulation and Delaunay refinement, the only file that sees CGAL.
 *
 * Kernel: exact predicates, inexact constructions (Epick). Constraint crossings that would need a
 * new (constructed) vertex are rejected rather than resolved, so that with max_edge == 0 the
 * vertices are exactly the input points (lib/core/cdt.h); a segment running through an input point is
 * split there, which needs no construction. The domain is marked on CGAL's own in_domain face flag
 * (Delaunay_mesh_face_base_2), which Delaunay_mesher_2 maintains while it inserts points, so the
 * mesher only refines the kept region and we read the kept triangles from the same flag. */
#include "cdt.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <new>
#include <utility>
#include <vector>

namespace {

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;

/* Input id of a vertex; -1 for Steiner points (the mesher default-constructs the info). */
struct Vinfo {
    plume_index id = -1;
};

typedef CGAL::Triangulation_vertex_base_with_info_2<Vinfo, K> Vb;
typedef CGAL::Delaunay_mesh_face_base_2<K> Fb;
typedef CGAL::Triangulation_data_structure_2<Vb, Fb> Tds;
typedef CGAL::No_constraint_intersection_requiring_constructions_tag Itag;
typedef CGAL::Constrained_Delaunay_triangulation_2<K, Tds, Itag> CDT;
typedef CGAL::Delaunay_mesh_size_criteria_2<CDT> Criteria;
typedef CGAL::Delaunay_mesher_2<CDT, Criteria> Mesher;
typedef CDT::Point Point;
typedef CDT::Vertex_handle Vertex_handle;
typedef CDT::Face_handle Face_handle;

/* Shape bound used when the caller passes 0: sin^2(20.7 deg), the largest with CGAL's termination
 * guarantee. Above kMaxShapeBound (30 deg) Delaunay refinement practically never terminates. */
const double kDefaultShapeBound = 0.125;
const double kMaxShapeBound = 0.25;
/* Refusing absurd max_edge values (typically a unit mistake) beats an OOM kill: the estimated
 * number of triangles, bounding-box area over an equilateral triangle of side max_edge. */
const double kMaxEstimatedTriangles = 2e9;

/* Marks the region reachable from f without crossing a constrained edge as out of the domain. */
void remove_region(Face_handle f, std::vector<Face_handle> &stack)
{
    if (!f->is_in_domain())
        return;
    f->set_in_domain(false);
    stack.clear();
    stack.push_back(f);
    while (!stack.empty()) {
        Face_handle g = stack.back();
        stack.pop_back();
        for (int i = 0; i < 3; i++) {
            Face_handle n = g->neighbor(i);
            if (!g->is_constrained(i) && n->is_in_domain()) {
                n->set_in_domain(false);
                stack.push_back(n);
            }
        }
    }
}

plume_status validate(const plume_cdt_input *in, plume_err *err)
{
    if (in->npoints < 3)
        return plume_err_set(err, PLUME_EINVAL, "cdt: npoints = %ld: at least 3 points are needed",
                             in->npoints);
    if (!in->points)
        return plume_err_set(err, PLUME_EINVAL, "cdt: points is NULL with npoints = %ld", in->npoints);
    for (plume_index i = 0; i < in->npoints; i++) {
        double x = in->points[2 * i], y = in->points[2 * i + 1];
        if (!std::isfinite(x) || !std::isfinite(y))
            return plume_err_set(err, PLUME_EINVAL, "cdt: point %ld: coordinates (%g, %g) are not finite",
                                 i, x, y);
    }
    if (in->nsegments < 0 || (in->nsegments > 0 && !in->segments))
        return plume_err_set(err, PLUME_EINVAL, "cdt: nsegments = %ld with segments %s", in->nsegments,
                             in->segments ? "set" : "NULL");
    for (plume_index s = 0; s < in->nsegments; s++) {
        for (int k = 0; k < 2; k++) {
            plume_index id = in->segments[2 * s + k];
            if (id < 0 || id >= in->npoints)
                return plume_err_set(err, PLUME_EINVAL, "cdt: segment %ld: point id %ld out of range [0, %ld)",
                                     s, id, in->npoints);
        }
        if (in->segments[2 * s] == in->segments[2 * s + 1])
            return plume_err_set(err, PLUME_EINVAL, "cdt: segment %ld: both endpoints are point %ld", s,
                                 in->segments[2 * s]);
    }
    if (in->nholes < 0 || (in->nholes > 0 && !in->holes))
        return plume_err_set(err, PLUME_EINVAL, "cdt: nholes = %ld with holes %s", in->nholes,
                             in->holes ? "set" : "NULL");
    for (plume_index h = 0; h < in->nholes; h++) {
        double x = in->holes[2 * h], y = in->holes[2 * h + 1];
        if (!std::isfinite(x) || !std::isfinite(y))
            return plume_err_set(err, PLUME_EINVAL, "cdt: hole %ld: coordinates (%g, %g) are not finite", h,
                                 x, y);
    }
    if (!std::isfinite(in->max_edge) || in->max_edge < 0)
        return plume_err_set(err, PLUME_EINVAL, "cdt: max_edge = %g must be finite and >= 0", in->max_edge);
    if (!std::isfinite(in->min_angle_bound) || in->min_angle_bound < 0 ||
        in->min_angle_bound > kMaxShapeBound)
        return plume_err_set(err, PLUME_EINVAL,
                             "cdt: min_angle_bound = %g must be in [0, %g] (sin^2 of the minimum angle; "
                             "0 selects %g)",
                             in->min_angle_bound, kMaxShapeBound, kDefaultShapeBound);
    return PLUME_OK;
}

/* Duplicate points would silently merge into one CGAL vertex and lose an id: reject them. */
plume_status check_duplicates(const plume_cdt_input *in, plume_err *err)
{
    const double *p = in->points;
    std::vector<plume_index> order(static_cast<size_t>(in->npoints));
    for (plume_index i = 0; i < in->npoints; i++)
        order[static_cast<size_t>(i)] = i;
    std::sort(order.begin(), order.end(), [p](plume_index a, plume_index b) {
        if (p[2 * a] != p[2 * b])
            return p[2 * a] < p[2 * b];
        if (p[2 * a + 1] != p[2 * b + 1])
            return p[2 * a + 1] < p[2 * b + 1];
        return a < b;
    });
    for (size_t k = 1; k < order.size(); k++) {
        plume_index a = order[k - 1], b = order[k];
        if (p[2 * a] == p[2 * b] && p[2 * a + 1] == p[2 * b + 1])
            return plume_err_set(err, PLUME_EINVAL, "cdt: points %ld and %ld are duplicates (%g, %g)", a, b,
                                 p[2 * a], p[2 * a + 1]);
    }
    return PLUME_OK;
}

/* With max_edge > 0, refuses a refinement that would need more than kMaxEstimatedTriangles. */
plume_status check_refinement_size(const plume_cdt_input *in, plume_err *err)
{
    if (!(in->max_edge > 0))
        return PLUME_OK;
    const plume_index n = in->npoints;
    double x0 = in->points[0], x1 = x0, y0 = in->points[1], y1 = y0;
    for (plume_index i = 1; i < n; i++) {
        x0 = std::min(x0, in->points[2 * i]);
        x1 = std::max(x1, in->points[2 * i]);
        y0 = std::min(y0, in->points[2 * i + 1]);
        y1 = std::max(y1, in->points[2 * i + 1]);
    }
    double est = (x1 - x0) * (y1 - y0) / (std::sqrt(3.0) / 4 * in->max_edge * in->max_edge);
    if (!(est <= kMaxEstimatedTriangles))
        return plume_err_set(err, PLUME_EINVAL,
                             "cdt: max_edge = %g would need ~%.3g triangles over the %g x %g bounding box",
                             in->max_edge, est, x1 - x0, y1 - y0);
    return PLUME_OK;
}

/* The input points (each vertex keeping its input id) and segments into cdt. Fails when the points
 * are collinear or a segment crosses an earlier one away from an input point. */
plume_status insert_input(CDT &cdt, const plume_cdt_input *in, plume_err *err)
{
    const plume_index n = in->npoints;
    {
        std::vector<std::pair<Point, Vinfo>> pts(static_cast<size_t>(n));
        for (plume_index i = 0; i < n; i++) {
            pts[static_cast<size_t>(i)].first = Point(in->points[2 * i], in->points[2 * i + 1]);
            pts[static_cast<size_t>(i)].second.id = i;
        }
        cdt.insert(pts.begin(), pts.end()); /* spatially sorted bulk insertion keeping the infos */
    }
    if (cdt.dimension() < 2)
        return plume_err_set(err, PLUME_EINVAL, "cdt: the %ld points are collinear: no triangle", n);

    std::vector<Vertex_handle> vh(static_cast<size_t>(n));
    for (CDT::Finite_vertices_iterator v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
        vh[static_cast<size_t>(v->info().id)] = v;

    for (plume_index s = 0; s < in->nsegments; s++) {
        plume_index a = in->segments[2 * s], b = in->segments[2 * s + 1];
        try {
            cdt.insert_constraint(vh[static_cast<size_t>(a)], vh[static_cast<size_t>(b)]);
        } catch (const CDT::Intersection_of_constraints_exception &) {
            return plume_err_set(err, PLUME_EINVAL,
                                 "cdt: segment %ld (points %ld-%ld) crosses an earlier segment away from "
                                 "an input point",
                                 s, a, b);
        }
    }
    return PLUME_OK;
}

/* Domain: every finite face, minus the exterior (remove_exterior), minus the hole regions.
 * Without remove_exterior the convex hull is constrained so the mesher cannot grow it. Fails on a
 * hole that lies on a point or a segment. */
plume_status mark_domain(CDT &cdt, const plume_cdt_input *in, plume_err *err)
{
    for (CDT::All_faces_iterator f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
        f->set_in_domain(true); /* infinite faces too: the exterior flood crosses them */
    if (!in->remove_exterior) {
        std::vector<std::pair<Vertex_handle, Vertex_handle>> hull;
        CDT::Face_circulator fc = cdt.incident_faces(cdt.infinite_vertex()), done(fc);
        do {
            int i = fc->index(cdt.infinite_vertex());
            if (!fc->is_constrained(i))
                hull.emplace_back(fc->vertex(CDT::ccw(i)), fc->vertex(CDT::cw(i)));
        } while (++fc != done);
        for (const auto &e : hull)
            cdt.insert_constraint(e.first, e.second);
    }
    std::vector<Face_handle> stack;
    remove_region(cdt.infinite_face(), stack);
    for (plume_index h = 0; h < in->nholes; h++) {
        Point q(in->holes[2 * h], in->holes[2 * h + 1]);
        CDT::Locate_type lt;
        int li;
        Face_handle f = cdt.locate(q, lt, li);
        if (lt == CDT::VERTEX || (lt == CDT::EDGE && f->is_constrained(li)))
            return plume_err_set(err, PLUME_EINVAL,
                                 "cdt: hole %ld at (%g, %g) lies on a %s: it does not name one region", h,
                                 q.x(), q.y(), lt == CDT::VERTEX ? "point" : "segment");
        remove_region(f, stack); /* outside the hull: the exterior, already removed */
    }
    return PLUME_OK;
}

/* Output: input points in input order, then the Steiner points used by a kept triangle, in the
 * order the face loop meets them (deterministic for a given input); *out is filled only on
 * success. Fails when no triangle is kept. */
plume_status write_output(CDT &cdt, const plume_cdt_input *in, plume_cdt_output *out, plume_err *err)
{
    const plume_index n = in->npoints;
    plume_index ntri = 0;
    for (CDT::Finite_faces_iterator f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
        if (f->is_in_domain())
            ntri++;
    if (ntri == 0)
        return plume_err_set(err, PLUME_EINVAL,
                             "cdt: no triangle left: the segments enclose no region kept by "
                             "remove_exterior = %d and the %ld hole(s)",
                             in->remove_exterior, in->nholes);

    std::vector<Vertex_handle> steiner;
    plume_index *tri = static_cast<plume_index *>(std::malloc(3 * static_cast<size_t>(ntri) * sizeof *tri));
    if (!tri)
        return plume_err_set(err, PLUME_ENOMEM, "cdt: no memory for %ld triangles", ntri);
    plume_index t = 0;
    for (CDT::Finite_faces_iterator f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        if (!f->is_in_domain())
            continue;
        for (int k = 0; k < 3; k++) { /* CGAL faces are counter-clockwise */
            Vertex_handle v = f->vertex(k);
            if (v->info().id < 0) {
                v->info().id = n + static_cast<plume_index>(steiner.size());
                steiner.push_back(v);
            }
            tri[3 * t + k] = v->info().id;
        }
        t++;
    }
    plume_index np = n + static_cast<plume_index>(steiner.size());
    double *pts = static_cast<double *>(std::malloc(2 * static_cast<size_t>(np) * sizeof *pts));
    if (!pts) {
        std::free(tri);
        return plume_err_set(err, PLUME_ENOMEM, "cdt: no memory for %ld points", np);
    }
    std::copy(in->points, in->points + 2 * n, pts);
    for (size_t k = 0; k < steiner.size(); k++) {
        pts[2 * (static_cast<size_t>(n) + k)] = steiner[k]->point().x();
        pts[2 * (static_cast<size_t>(n) + k) + 1] = steiner[k]->point().y();
    }
    out->npoints = np;
    out->points = pts;
    out->ntriangles = ntri;
    out->triangles = tri;
    return PLUME_OK;
}

plume_status triangulate(const plume_cdt_input *in, plume_cdt_output *out, plume_err *err)
{
    plume_status st;
    if ((st = validate(in, err)) != PLUME_OK || (st = check_duplicates(in, err)) != PLUME_OK ||
        (st = check_refinement_size(in, err)) != PLUME_OK)
        return st;
    CDT cdt;
    if ((st = insert_input(cdt, in, err)) != PLUME_OK || (st = mark_domain(cdt, in, err)) != PLUME_OK)
        return st;
    if (in->max_edge > 0) {
        double b = in->min_angle_bound > 0 ? in->min_angle_bound : kDefaultShapeBound;
        Mesher mesher(cdt, Criteria(b, in->max_edge));
        mesher.init(true); /* keep our marks: CGAL only re-clears the infinite component */
        mesher.refine_mesh();
    }
    return write_output(cdt, in, out, err);
}

} // namespace

extern "C" plume_status plume_cdt_triangulate(const plume_cdt_input *in, plume_cdt_output *out,
                                              plume_err *err)
{
    if (!out)
        return plume_err_set(err, PLUME_EINVAL, "cdt: output is NULL");
    *out = plume_cdt_output{0, nullptr, 0, nullptr};
    if (!in)
        return plume_err_set(err, PLUME_EINVAL, "cdt: input is NULL");
    /* Nothing allocated with malloc survives a throw: out is only filled at the very end. */
    try {
        return triangulate(in, out, err);
    } catch (const std::bad_alloc &) {
        return plume_err_set(err, PLUME_ENOMEM, "cdt: out of memory in CGAL");
    } catch (const std::exception &e) {
        return plume_err_set(err, PLUME_EDEP, "cdt: CGAL failed: %s", e.what());
    } catch (...) {
        return plume_err_set(err, PLUME_EDEP, "cdt: CGAL failed with an unknown exception");
    }
}

extern "C" void plume_cdt_output_free(plume_cdt_output *out)
{
    if (!out)
        return;
    std::free(out->points);
    std::free(out->triangles);
    *out = plume_cdt_output{0, nullptr, 0, nullptr};
}
