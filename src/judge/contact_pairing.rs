//! A trace's contact queries paired with their answers and judged
//! ([`ContactPairing`]): the fold `check` and the recording share, over
//! [`super::contacts::judge_contacts`].

use crate::conventions::EngineConventions;
use crate::core::Mesh;
use crate::core::topology::Topology;
use crate::replay::SceneNormals;
use crate::trace::{ContactMsg, ContactsMsg};

use super::Tolerances;
use super::contacts::{ContactScene, ContactVerdict, judge_contacts};

/// A scene built for judging contacts.
struct Built {
    mesh: Mesh,
    topology: Topology,
    normals: SceneNormals,
}

/// One query judged by [`ContactPairing`], with what it was judged on (the
/// recording draws them; `check` reads the verdict only).
pub(crate) struct PairedContacts {
    /// The query.
    pub(crate) query: ContactMsg,
    /// Its `log_time` (the query's).
    pub(crate) log_time_nanos: u64,
    /// The answer judged.
    pub(crate) answer: ContactsMsg,
    /// The judgement.
    pub(crate) verdict: ContactVerdict,
}

/// A query paired with its answer, not yet judged
/// ([`ContactPairing::judge`]).
pub(crate) struct Pair {
    query: ContactMsg,
    log_time_nanos: u64,
    answer: ContactsMsg,
}

/// A trace's contact queries paired with their answers (the `/contact` and
/// `/expected_contacts` of one frame and ball, in either order, within one
/// scene) and judged against the scene: the fold `check` and the recording
/// share.
pub(crate) struct ContactPairing<'a> {
    tolerances: &'a Tolerances,
    conventions: &'a EngineConventions,
    ghost_degrees: f64,
    /// The current scene's message, built at its first judged query.
    scene: Option<crate::trace::SceneMsg>,
    built: Option<Option<Built>>,
    queries: std::collections::HashMap<(u64, u32), (ContactMsg, u64)>,
    answers: std::collections::HashMap<(u64, u32), ContactsMsg>,
    /// Queries left without an answer (in their scene).
    pub(crate) without_answer: u64,
    /// Answers left without a query.
    pub(crate) answers_without_query: u64,
    /// What could not be judged (a scene without a usable triangle).
    pub(crate) errors: Vec<String>,
}

impl<'a> ContactPairing<'a> {
    pub(crate) fn new(
        tolerances: &'a Tolerances,
        conventions: &'a EngineConventions,
        ghost_degrees: f64,
    ) -> Self {
        ContactPairing {
            tolerances,
            conventions,
            ghost_degrees,
            scene: None,
            built: None,
            queries: Default::default(),
            answers: Default::default(),
            without_answer: 0,
            answers_without_query: 0,
            errors: Vec::new(),
        }
    }

    /// A new scene: the previous one's unpaired queries and answers are
    /// counted as such.
    pub(crate) fn scene(&mut self, scene: &crate::trace::SceneMsg) {
        self.flush();
        self.scene = Some(scene.clone());
        self.built = None;
    }

    /// A query at `log_time_nanos`; judged when its answer came first.
    pub(crate) fn query(
        &mut self,
        query: &ContactMsg,
        log_time_nanos: u64,
    ) -> Option<PairedContacts> {
        let pair = self.pair_query(query, log_time_nanos)?;
        self.judge(pair)
    }

    /// An answer; judged when its query came first.
    pub(crate) fn answer(&mut self, answer: &ContactsMsg) -> Option<PairedContacts> {
        let pair = self.pair_answer(answer)?;
        self.judge(pair)
    }

    /// A query at `log_time_nanos`: the pair to judge (with
    /// [`ContactPairing::judge`]) when its answer came first.
    pub(crate) fn pair_query(&mut self, query: &ContactMsg, log_time_nanos: u64) -> Option<Pair> {
        let key = (query.frame, query.ball);
        match self.answers.remove(&key) {
            Some(answer) => self.paired(*query, log_time_nanos, answer),
            None => {
                if self.queries.insert(key, (*query, log_time_nanos)).is_some() {
                    self.without_answer += 1;
                }
                None
            }
        }
    }

    /// An answer: the pair to judge (with [`ContactPairing::judge`]) when
    /// its query came first.
    pub(crate) fn pair_answer(&mut self, answer: &ContactsMsg) -> Option<Pair> {
        let key = (answer.frame, answer.ball);
        match self.queries.remove(&key) {
            Some((query, log_time_nanos)) => self.paired(query, log_time_nanos, answer.clone()),
            None => {
                if self.answers.insert(key, answer.clone()).is_some() {
                    self.answers_without_query += 1;
                }
                None
            }
        }
    }

    /// Counts what is left unpaired (at a scene's end and the trace's).
    pub(crate) fn flush(&mut self) {
        self.without_answer += self.queries.len() as u64;
        self.answers_without_query += self.answers.len() as u64;
        self.queries.clear();
        self.answers.clear();
    }

    /// A query and its answer, once the scene is built for them (none when
    /// the scene has no usable triangle: said in `errors` once).
    fn paired(
        &mut self,
        query: ContactMsg,
        log_time_nanos: u64,
        answer: ContactsMsg,
    ) -> Option<Pair> {
        let normal = self.conventions.normal;
        let scene = &self.scene;
        let built = self.built.get_or_insert_with(|| {
            let scene = scene.as_ref()?;
            let mesh = Mesh::new(scene.vertices.clone(), &scene.triangles).ok()?;
            let topology = Topology::new(&scene.vertices, &scene.triangles).ok()?;
            let normals = SceneNormals::new(normal, &mesh, &topology);
            Some(Built {
                mesh,
                topology,
                normals,
            })
        });
        if built.is_none() {
            if self.errors.is_empty() {
                self.errors.push(format!(
                    "frame {}, ball {}: the contact query's scene has no usable triangle, so contacts cannot be judged",
                    query.frame, query.ball
                ));
            }
            return None;
        }
        Some(Pair {
            query,
            log_time_nanos,
            answer,
        })
    }

    /// Judges `pair` against the current scene (the one it was paired in:
    /// judge a scene's pairs before the next [`ContactPairing::scene`]).
    /// Takes `&self`, so that the pairs of a scene can be judged in
    /// parallel.
    pub(crate) fn judge(&self, pair: Pair) -> Option<PairedContacts> {
        let Some(Some(built)) = &self.built else {
            return None;
        };
        let Pair {
            query,
            log_time_nanos,
            answer,
        } = pair;
        let scene = ContactScene {
            mesh: &built.mesh,
            topology: &built.topology,
            normals: &built.normals,
        };
        let mut verdict = judge_contacts(
            &scene,
            &query,
            &answer,
            self.tolerances,
            self.conventions,
            self.ghost_degrees,
        );
        for ghost in &mut verdict.ghosts {
            ghost.log_time_nanos = log_time_nanos;
        }
        Some(PairedContacts {
            query,
            log_time_nanos,
            answer,
            verdict,
        })
    }
}
