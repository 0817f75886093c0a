//! Changing who stands in a garden, and editing a tree outside the garden: what a design needs
//! when trees are planted one by one, removed, and edited over many frames by tools that hold
//! the tree themselves.
//!
//! A tree taken out for editing ([`Garden::prepare_edit`], then a copy of its tree) is edited
//! against its neighbours as they stand: its environment holds their nodes as occupied space,
//! their asymmetry tropism and all their shade. Put back ([`Garden::replace_tree`]), the change
//! of its nodes is handed on to the shade of the trees it reaches, as [`Garden::edit_tree`]
//! does; no other tree changes. Its own grid is made anew then (its own nodes and all its
//! linked neighbours'): the copy may have been restored by an undo, which rebuilds a grid from
//! the tree's own nodes alone.

use super::competition::{self, NodeChanges, node_ends};
use super::planting::{MAX_GARDEN_TREES, MIN_TREE_SPACING_M, check_point};
use super::{Garden, GardenError, GardenTree, MAX_GARDEN_YEARS, cache, index, shade};
use crate::Tree;

impl Garden {
    /// A garden without trees (competition on): trees come in by [`Garden::add_tree`].
    pub fn empty() -> Garden {
        Garden {
            trees: Vec::new(),
            years: 0.0,
            competition: true,
        }
    }

    /// Plants `tree`, grown elsewhere, with its trunk base at `(x_m, 0, z_m)`; returns its
    /// index. Refused (an error naming the tree) when the position is not finite or too far
    /// out, a trunk stands within [`MIN_TREE_SPACING_M`], the planting age is out of range or
    /// the garden is full. The neighbours reach its environment at the next round or edit.
    pub fn add_tree(
        &mut self,
        x_m: f32,
        z_m: f32,
        planting_age_years: f32,
        seed: u64,
        tree: Tree,
    ) -> Result<usize, GardenError> {
        let index = self.trees.len();
        let entry = format!("tree {index}");
        let bad = |reason: String| GardenError::Planting {
            entry: entry.clone(),
            reason,
        };
        if index >= MAX_GARDEN_TREES {
            return Err(bad(format!(
                "the garden already holds {MAX_GARDEN_TREES} trees"
            )));
        }
        check_point(&entry, glam::Vec2::new(x_m, z_m))?;
        if !(planting_age_years.is_finite()
            && (0.0..=MAX_GARDEN_YEARS).contains(&planting_age_years))
        {
            return Err(bad(format!(
                "planting age {planting_age_years} years, expected 0 to {MAX_GARDEN_YEARS}"
            )));
        }
        if let Some((j, other)) =
            self.trees.iter().enumerate().find(|(_, t)| {
                glam::Vec2::new(t.x_m - x_m, t.z_m - z_m).length() < MIN_TREE_SPACING_M
            })
        {
            return Err(bad(format!(
                "its trunk at ({x_m}, {z_m}) is within {MIN_TREE_SPACING_M} m of tree {j}'s at ({}, {})",
                other.x_m, other.z_m
            )));
        }
        self.trees.push(GardenTree {
            x_m,
            z_m,
            planting_age_years,
            seed,
            tree,
            neighbours: Vec::new(),
            shade_cover: shade::ShadeCover::default(),
            node_index: index::NodeIndex::default(),
            cache: cache::EditCache {
                version: cache::fresh_version(),
                ..Default::default()
            },
        });
        Ok(index)
    }

    /// Removes tree `index`: its shade is taken from the grids of the trees it reached and the
    /// links are renumbered. None (and nothing changes) for an index past the trees.
    pub fn remove_tree(&mut self, index: usize) -> Option<GardenTree> {
        if index >= self.trees.len() {
            return None;
        }
        let removed = self.trees.remove(index);
        let ends = node_ends(&removed);
        let gone = index as u32;
        for t in &mut self.trees {
            if t.neighbours.contains(&gone) {
                let base = t.base();
                let cover = &t.shade_cover;
                // The grid holds exactly the neighbour's nodes its cover covers (module
                // `competition`): those are taken away.
                t.tree.environment.shadow.apply_nodes(
                    ends.iter().map(|&p| p - base).filter(|&p| cover.covers(p)),
                    -1,
                );
            }
            t.neighbours.retain(|&j| j != gone);
            for j in &mut t.neighbours {
                if *j > gone {
                    *j -= 1;
                }
            }
        }
        Some(removed)
    }

    /// Readies tree `index` for edits made outside the garden (a copy of its tree edited by a
    /// design's tools): linked to the trees within reach, their nodes as occupied space, their
    /// asymmetry tropism and all their shade in its environment. False for an index past the
    /// trees.
    pub fn prepare_edit(&mut self, index: usize) -> bool {
        if index >= self.trees.len() {
            return false;
        }
        if !self.competition {
            return true;
        }
        let mut due = vec![false; self.trees.len()];
        due[index] = true;
        competition::link_neighbours(self);
        competition::give_all_neighbour_nodes(self, index);
        competition::set_neighbour_tropisms(self, &due);
        competition::set_shade_everywhere(self, index);
        true
    }

    /// Puts back tree `index` as it was edited outside (see [`Garden::prepare_edit`]): the
    /// change of its nodes goes to the shade of the trees it reaches, and its own grid is made
    /// anew from its nodes and all its linked neighbours'. No other tree changes. False (and
    /// nothing changes) for an index past the trees.
    pub fn replace_tree(&mut self, index: usize, tree: Tree) -> bool {
        if index >= self.trees.len() {
            return false;
        }
        let before = node_ends(&self.trees[index]);
        let before_iteration = self.trees[index].tree.iteration;
        self.trees[index].tree = tree;
        self.trees[index].cache.changed();
        if !self.competition {
            return true;
        }
        let others: Vec<glam::Vec3> = self.trees[index]
            .neighbours
            .iter()
            .flat_map(|&j| node_ends(&self.trees[j as usize]))
            .collect();
        let t = &mut self.trees[index];
        let base = t.base();
        t.tree.rebuild_shadow();
        t.tree
            .environment
            .shadow
            .apply_nodes(others.into_iter().map(|p| p - base), 1);
        if !t.shade_cover.is_made() {
            t.shade_cover = shade::ShadeCover::of(&t.tree);
        }
        t.shade_cover.everywhere = true;
        let mut changes: Vec<Option<NodeChanges>> = (0..self.trees.len()).map(|_| None).collect();
        changes[index] = Some(NodeChanges::of(
            &self.trees[index],
            &before,
            before_iteration,
        ));
        self.trees[index].node_index = index::NodeIndex::default();
        competition::hand_on_shade(self, &changes);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::species::Species;

    fn birch(seed: u64) -> Tree {
        let species = Species::by_name("birch").unwrap_or_else(|_| Species::presets().remove(0));
        let mut tree = Tree::new(species, seed);
        tree.grow_years(6.0);
        tree
    }

    fn shade_at_nodes(g: &Garden, i: usize) -> Vec<f32> {
        let t = &g.trees[i].tree;
        t.skeleton
            .internodes
            .iter()
            .map(|n| t.environment.shadow.shadow_at(n.end))
            .collect()
    }

    #[test]
    fn a_tree_added_then_removed_leaves_its_neighbours_shade_as_it_was() {
        let mut g = Garden::empty();
        g.add_tree(0.0, 0.0, 0.0, 1, birch(1)).expect("first");
        g.add_tree(1.5, 0.0, 0.0, 2, birch(2)).expect("second");
        g.prepare_edit(0);
        let with_one = shade_at_nodes(&g, 0);
        g.add_tree(0.0, 1.5, 0.0, 3, birch(3)).expect("third");
        g.prepare_edit(0);
        assert_ne!(
            shade_at_nodes(&g, 0),
            with_one,
            "the third tree shades the first"
        );
        g.remove_tree(2).expect("removed");
        assert_eq!(shade_at_nodes(&g, 0), with_one);
        assert_eq!(g.trees[0].neighbours, vec![1]);
    }

    #[test]
    fn a_tree_on_another_trunk_or_off_the_plot_is_refused_naming_it() {
        let mut g = Garden::empty();
        g.add_tree(0.0, 0.0, 0.0, 1, birch(1)).expect("first");
        let err = g.add_tree(0.1, 0.0, 0.0, 2, birch(2)).unwrap_err();
        assert!(err.to_string().contains("tree 1"), "{err}");
        assert!(g.add_tree(f32::NAN, 0.0, 0.0, 2, birch(2)).is_err());
        assert_eq!(g.trees.len(), 1);
    }

    #[test]
    fn a_tree_edited_outside_and_put_back_matches_the_same_edit_inside() {
        let mut inside = Garden::empty();
        inside.add_tree(0.0, 0.0, 0.0, 1, birch(1)).expect("first");
        inside.add_tree(1.5, 0.0, 0.0, 2, birch(2)).expect("second");
        let mut outside = inside.clone();
        inside.edit_tree(1, |t| {
            t.grow(3, None);
        });
        outside.prepare_edit(1);
        let mut copy = outside.trees[1].tree.clone();
        copy.grow(3, None);
        outside.replace_tree(1, copy);
        assert_eq!(
            inside.trees[1].tree.to_json_bytes().expect("saves"),
            outside.trees[1].tree.to_json_bytes().expect("saves")
        );
        assert_eq!(shade_at_nodes(&inside, 0), shade_at_nodes(&outside, 0));
        assert_eq!(shade_at_nodes(&inside, 1), shade_at_nodes(&outside, 1));
    }
}
