pub use voxgi_scene;
