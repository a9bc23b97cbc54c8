//! The scene's paths against each other and against closed forms.
